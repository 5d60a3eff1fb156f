#!/bin/sh
# Remakes the gallery from the scenes and benchmarks (Release build).
set -eu
cd "$(dirname "$0")/.."
scripts/install-deps.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"$(nproc)"
build/bench_accuracy_time gallery
gallery/render.sh build
gallery/selfcol.sh build
# strong scaling at 1 and 2 ranks (more where the machine has the cores)
bench/scaling.sh build 1 2
