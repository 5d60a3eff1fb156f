#!/bin/sh
# The long tests (ctest label `long`: the paper figures at their test size,
# every frame checked, and the twist under the hold policy), which scripts/test.sh and CI leave out: builds the
# same ASan+UBSan tree as scripts/test.sh and runs only them.
set -eu
cd "$(dirname "$0")/.."
scripts/install-deps.sh
scripts/configure.sh build-asan Asan
cmake --build build-asan -j"$(nproc)"
cd build-asan && exec ctest --output-on-failure -j"$(nproc)" -L long "$@"
