#!/bin/sh
# gallery/selfcol.sh [BUILD_DIR]: remakes the self-collision pictures
# (called by gallery/make.sh; BUILD_DIR defaults to build, a Release build):
#   twist.png          scenes/twist.yaml after 1 s (24 frames), ray traced
#   curtain_ball.png   scenes/curtain_ball.yaml at frame 26: the sheet flipped
#                      over itself with the ball pressing into the folds
# Every frame of both runs is checked by the verifier (summary.json).
set -eu
cd "$(dirname "$0")/.."
BUILD=${1:-build}
OUT=out/gallery
"$BUILD/clothsim" run scenes/twist.yaml -q --frames 24 -o "$OUT/twist" >/dev/null
"$BUILD/clothsim" render "$OUT/twist" -q --frames last --size 480x360 --samples 16 \
    -o "$OUT/twist_images"
cp "$OUT/twist_images/frame_0024.png" gallery/twist.png
"$BUILD/clothsim" run scenes/curtain_ball.yaml -q -o "$OUT/curtain_ball" >/dev/null
"$BUILD/clothsim" render "$OUT/curtain_ball" -q --frames 26 --size 480x360 --samples 16 \
    -o "$OUT/curtain_ball_images"
cp "$OUT/curtain_ball_images/frame_0026.png" gallery/curtain_ball.png
