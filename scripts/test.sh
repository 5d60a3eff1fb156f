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
# Ninja starts every target's compiles at once (make waits for a target's
# libraries first and left a core idle behind the OpenVDB shim); a build
# folder made before keeps its generator.
configure() { # DIR TYPE
    generator=""
    [ -f "$1/CMakeCache.txt" ] || generator="-GNinja"
    cmake $generator -S . -B "$1" -DCMAKE_BUILD_TYPE="$2" >/dev/null
}
configure build-asan Asan
cmake --build build-asan -j"$(nproc)"
if [ "$#" -eq 0 ]; then
    set -- -LE long
    memcheck=yes
fi
(cd build-asan && ctest --output-on-failure -j"$(nproc)" "$@")
if [ "${memcheck:-}" = yes ]; then
    configure build-memcheck RelWithDebInfo
    cmake --build build-memcheck -j"$(nproc)" --target clothsim
    sh tests/memcheck.sh "$PWD/build-memcheck/clothsim" "$PWD"
fi
