#!/bin/sh
# fuzz/build.sh: builds the libFuzzer targets with clang into
# build-fuzz/ (or $1), a separate CMake build of the whole project with
# -DCS_FUZZ=ON, every library instrumented for coverage
# (-fsanitize=fuzzer-no-link) and checked by AddressSanitizer and
# UndefinedBehaviorSanitizer; the targets link libFuzzer. Then lays the
# seed corpus (fuzz/seed.sh). Needs clang (Debian's clang-14) besides what
# scripts/install-deps.sh installs; not part of CI.
#   fuzz/build.sh [BUILD_DIR]      # default: build-fuzz
# Set JOBS to change the parallel build jobs (default 1: a shared machine).
set -eu
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-"$root/build-fuzz"}
jobs=${JOBS:-1}
command -v clang >/dev/null || { echo "fuzz/build.sh: needs clang (apt-get install clang)" >&2; exit 1; }

flags="-O1 -g -fno-omit-frame-pointer -fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=undefined"
# The one C++ file (the OpenVDB shim) without UBSan's alignment check: TBB's
# concurrent_hash_map (under OpenVDB's grid conversion) casts small tag
# values to node pointers by design (concurrent_hash_map.h:446, "downcast
# of misaligned address 0x3"), which would stop every scene with a mesh body.
CC=clang CXX=clang++ cmake -S "$root" -B "$build" -DCS_FUZZ=ON -DCMAKE_BUILD_TYPE=Fuzz \
    -DCMAKE_C_FLAGS_FUZZ="$flags" -DCMAKE_CXX_FLAGS_FUZZ="$flags -fno-sanitize=alignment" \
    -DCMAKE_EXE_LINKER_FLAGS_FUZZ="-fsanitize=address,undefined" \
    -DCMAKE_SHARED_LINKER_FLAGS_FUZZ="-fsanitize=address,undefined"
# the fuzz targets and the regression test only, not the whole project
cmake --build "$build" -j "$jobs" --target scene_fuzz mesh_fuzz test_fuzz_regressions
sh "$root/fuzz/seed.sh" "$build"
echo "built $build/fuzz/scene_fuzz and $build/fuzz/mesh_fuzz; see fuzz/README.md to run them"
