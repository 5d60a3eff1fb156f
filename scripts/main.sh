#!/bin/sh
# The main job: installs what is missing, builds, and simulates a scene
# (by default the demo drape) into out/<scene name>/.
set -eu
cd "$(dirname "$0")/.."
scripts/install-deps.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"$(nproc)"
SCENE="${1:-scenes/drape.yaml}"
# The demo is also ray traced frame by frame into out/drape/images/.
RENDER=""
[ $# -eq 0 ] && RENDER="--render embree --size 480x360 --samples 8"
[ $# -gt 0 ] && shift
NAME="$(basename "$SCENE" .yaml)"
# shellcheck disable=SC2086
exec build/clothsim run "$SCENE" -o "out/$NAME" $RENDER "$@"
