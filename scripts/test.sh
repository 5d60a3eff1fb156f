#!/bin/sh
# The test command: installs what is missing, builds with AddressSanitizer and
# UndefinedBehaviorSanitizer, and runs the whole suite through ctest; then
# (with no ctest arguments) valgrind's memcheck on a build without
# sanitizers, for the uninitialised reads ASan cannot see.
set -eu
cd "$(dirname "$0")/.."
scripts/install-deps.sh
cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=Asan >/dev/null
cmake --build build-asan -j"$(nproc)"
(cd build-asan && ctest --output-on-failure -j"$(nproc)" "$@")
if [ "$#" -eq 0 ]; then
    cmake -S . -B build-memcheck -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
    cmake --build build-memcheck -j"$(nproc)" --target clothsim
    sh tests/memcheck.sh "$PWD/build-memcheck/clothsim" "$PWD"
fi
