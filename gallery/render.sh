#!/bin/sh
# gallery/render.sh [BUILD_DIR]: remakes the rendered pictures of the gallery
# (called by gallery/make.sh; BUILD_DIR defaults to build, a Release build):
#   drape.png            scenes/drape.yaml's last frame, ray traced
#   drape_turntable.png  a turntable of that frame, as a contact sheet
#   drape_preview.png    the OSMesa preview halfway through the fall, with
#                        the mesh drawn over it
# The run and the full-size images go to out/gallery/.
set -eu
cd "$(dirname "$0")/.."
BUILD=${1:-build}
OUT=out/gallery
rm -rf "$OUT"
"$BUILD/clothsim" run scenes/drape.yaml -q -o "$OUT/drape" >/dev/null
# A narrower field of view than the scene's brings the drape closer.
"$BUILD/clothsim" render "$OUT/drape" -q --frames last --size 480x360 --samples 64 \
    --set camera.fov=27 -o "$OUT/final"
cp "$OUT"/final/frame_*.png gallery/drape.png
"$BUILD/clothsim" render "$OUT/drape" -q --frames last --turntable 8 --size 320x240 \
    --samples 64 --set camera.fov=30 -o "$OUT/turntable"
cp "$OUT/turntable/contact_sheet.png" gallery/drape_turntable.png
"$BUILD/clothsim" render "$OUT/drape" -q --engine preview --wireframe --frames 12 \
    --size 480x360 --samples 8 --set camera.fov=27 -o "$OUT/preview"
cp "$OUT/preview/frame_0012.png" gallery/drape_preview.png
ls -l gallery/drape.png gallery/drape_turntable.png gallery/drape_preview.png
