#!/bin/sh
# cli_usd.sh CLOTHSIM_EXE SOURCE_DIR: `run -o DIR` writes DIR/cloth.usda and
# `export DIR --format usd` writes it again, the same bytes. TinyUSDZ (a
# reader we did not write: npm's tinyusdz, WebAssembly under node) and a
# small parse of the test's own (tests/usd_check.mjs) find the mesh prims,
# their point and face counts, the time samples and codes, and points equal
# to the frame files at two time codes (and triangles with the frames'
# corners), for the drape, the twisting strip
# and a scene of awkward names, two cloths and a moving body. A run that
# blows up (exit 3) leaves a cloth.usda of the frames it wrote. Skipped
# (77) without node, or when tinyusdz cannot be installed.
set -eu

NAME=cli_usd
. "$2/tests/harness.sh"
SRC=$2

# the reader: installed once into the build tree, then reused
command -v node >/dev/null 2>&1 || { echo "$NAME: SKIP: node is not installed"; exit 77; }
NPM_DIR=${CS_NPM_DIR:-$(dirname "$EXE")/npm}
MODULES=$NPM_DIR/node_modules
if [ ! -f "$MODULES/tinyusdz/tinyusdz.wasm" ]; then
    command -v npm >/dev/null 2>&1 || { echo "$NAME: SKIP: npm is not installed"; exit 77; }
    mkdir -p "$NPM_DIR"
    if ! timeout 300 npm install --prefix "$NPM_DIR" --no-audit --no-fund --omit=dev \
        tinyusdz@0.9.0-rc10 >npm.txt 2>&1; then
        tail -5 npm.txt
        echo "$NAME: SKIP: the npm package tinyusdz could not be installed"
        exit 77
    fi
fi

# check_usd DIR SPEC: usd_check.mjs on DIR/cloth.usda
check_usd() {
    node "$SRC/tests/usd_check.mjs" "$MODULES" "$1/cloth.usda" "$2" >check.txt 2>&1 || {
        cat check.txt >&2
        fail "usd_check: $1/cloth.usda"
    }
    cat check.txt
}

# 1. the drape at a lower resolution: a sheet (21 x 21 vertices, 800
# triangles) over a static ball and ground
run 0 run "$SRC/scenes/drape.yaml" -o drape -q --frames 3 \
    --set 'cloths.0.grid.resolution=[20,20]'
grep -q 'animated USD stage: drape/cloth.usda' out.txt || fail "run does not name cloth.usda"
ls drape/*.tmp >/dev/null 2>&1 && fail "temporary files left in drape/"
cat >drape.json <<EOF
{"root": "drape", "up": "Y", "fps": 24, "start": 0, "end": 3, "times": [1, 3],
 "meshes": [{"name": "sheet", "given": "sheet", "points": 441, "faces": 800, "samples": 4,
             "frames": "drape/frames/frame_%04d.ply"}],
 "bodies": [{"name": "ball", "samples": 0}, {"name": "ground", "samples": 0}]}
EOF
check_usd drape drape.json
cp drape/cloth.usda run.usda
run 0 export drape --format usd
grep -q '^wrote drape/cloth.usda: 1 cloth, 2 bodies, time codes 0 to 3 at 24 per second' out.txt ||
    fail "export does not say what it wrote"
cmp -s run.usda drape/cloth.usda || fail "export wrote other bytes than run"

# 2. the twisting strip (self-collision, scripted ends), few frames, as OBJ
# frames: their reader orders the vertices its own way, which cloth.usda
# follows (points and triangles as the frame files hold them)
run 0 run "$SRC/tests/data/scenes/twist_3turns.yaml" -o twist -q --frames 2 --format obj
cat >twist.json <<EOF
{"root": "twist_3turns", "up": "Y", "fps": 24, "start": 0, "end": 2, "times": [0, 2],
 "meshes": [{"name": "sheet", "points": 561, "faces": 1024, "samples": 3,
             "frames": "twist/frames/frame_%04d.obj"}],
 "bodies": []}
EOF
check_usd twist twist.json

# 3. names that are not identifiers and clash once made so, a quote in a
# name, z up, and a box moving at constant velocity (a transform sample
# per frame)
cat >names.yaml <<'YAML'
name: 3 names
time: {fps: 30, frames: 2}
gravity: [0, 0, -9.8]
camera: {position: [3, 3, 2], target: [0, 0, 0], up: [0, 0, 1]}
cloths:
  - name: my sheet
    grid: {size: [0.5, 0.5], resolution: [4, 4], center: [-0.6, 0, 1], rotation: [90, 0, 0]}
  - name: my-sheet
    grid: {size: [0.5, 0.5], resolution: [6, 3], center: [0.6, 0, 1], rotation: [90, 0, 0]}
  - name: say "hi"
    grid: {size: [0.5, 0.5], resolution: [2, 2], center: [0, 0.8, 1], rotation: [90, 0, 0]}
bodies:
  - name: 2box
    shape: box
    size: [0.2, 0.2, 0.2]
    position: [0, 0, 0.2]
    motion: {velocity: [0.5, 0, 0]}
YAML
run 0 run names.yaml -o names -q --set output.usd=false
[ -e names/cloth.usda ] && fail "output.usd=false still wrote cloth.usda"
run 0 export names
cat >names.json <<EOF
{"root": "_3_names", "up": "Z", "fps": 30, "start": 0, "end": 2, "times": [0, 2],
 "meshes": [{"name": "my_sheet", "given": "my sheet", "points": 25, "faces": 32, "samples": 3,
             "frames": "names/frames/frame_%04d.my_sheet.ply"},
            {"name": "my_sheet_2", "given": "my-sheet", "points": 28, "faces": 36, "samples": 3,
             "frames": "names/frames/frame_%04d.my-sheet.ply"},
            {"name": "say__hi_", "given": "say \"hi\"", "points": 9, "faces": 8, "samples": 3,
             "frames": "names/frames/frame_%04d.say__hi_.ply"}],
 "bodies": [{"name": "_2box", "samples": 3}]}
EOF
check_usd names names.json

# 4. a run that blows up keeps a cloth.usda of the frames it wrote
run 3 run "$SRC/scenes/drape.yaml" --set 'cloths.0.grid.resolution=[16,16]' \
    --set cloths.0.material.edge_overdamping=0 --set cloths.0.material.bend_overdamping=0 \
    --set time.dt=0.0417 -o blown -q
written=$(ls blown/frames | wc -l)
[ "$written" -ge 2 ] || fail "the unstable run kept $written frames"
grep -q "^    endTimeCode = $((written - 1))\$" blown/cloth.usda ||
    fail "blown/cloth.usda does not end at frame $((written - 1))"
[ "$(grep -c '^            [0-9]*: \[' blown/cloth.usda)" -eq "$written" ] ||
    fail "blown/cloth.usda does not sample the $written frames written"

# bad input: a clear message and a status, never a crash
run 2 export nowhere
err_has 'cannot read nowhere'
mkdir empty
run 2 export empty
err_has 'empty has no summary.json'
run 2 export names.yaml
err_has 'names.yaml is not a folder'
run 1 export drape --format fbx
err_has "--format: 'fbx' is not one of usd, pc2"
run 1 export
err_has 'no run folder given'
rm drape/frames/frame_0002.ply
run 2 export drape
err_has 'frame_0002.ply: no such frame file'
cmp -s run.usda drape/cloth.usda || fail "a failed export replaced cloth.usda"
ls drape/*.tmp >/dev/null 2>&1 && fail "a failed export left temporary files"
run 0 help
grep -q '^  export DIR' out.txt || fail "'clothsim help' does not list export"
echo "$NAME: ok"
