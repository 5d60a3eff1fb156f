#!/bin/sh
# The test command: installs what is missing, builds with AddressSanitizer and
# UndefinedBehaviorSanitizer, and runs the suite through ctest, all but the
# tests labelled `long` (scripts/test-long.sh runs those); then valgrind's
# memcheck on a build without sanitizers, for the uninitialised reads ASan
# cannot see. With arguments, they go to ctest as given (`-R NAME` runs
# the tests named, long or not) and memcheck is left out.
set -eu
cd "$(dirname "$0")/.."
scripts/install-deps.sh
scripts/configure.sh build-asan Asan
cmake --build build-asan -j"$(nproc)"
if [ "$#" -eq 0 ]; then
    set -- -LE long
    memcheck=yes
fi
(cd build-asan && ctest --output-on-failure -j"$(nproc)" "$@")
if [ "${memcheck:-}" = yes ]; then
    scripts/configure.sh build-memcheck RelWithDebInfo
    cmake --build build-memcheck -j"$(nproc)" --target clothsim
    sh tests/memcheck.sh "$PWD/build-memcheck/clothsim" "$PWD"
fi
