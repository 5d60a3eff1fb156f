#!/bin/sh
# cli_standalone.sh CLOTHSIM_EXE SOURCE_DIR: a run folder stands alone. Its
# scene.yaml (every key with its value, written by libyaml) and assets/
# (the mesh files and level sets, named by their content) run the same
# frames bit for bit; once the scene file, its mesh and the level-set cache
# are gone, `render DIR` and `run DIR --resume` still work, and the resumed
# frames are those of a run never interrupted.
set -eu

NAME=cli_standalone
. "$2/tests/harness.sh"
SRC=$2

# hashes DIR: the state hashes of DIR/frames.jsonl, one a line
hashes() {
    python3 -c '
import json, sys
for line in open(sys.argv[1] + "/frames.jsonl"):
    print(json.loads(line)["state_hash"])' "$1"
}

mkdir src
cp "$SRC/assets/ico4.obj" src/ball.obj
# a mesh body, pins, a scripted corner, friction keys and wind: keys of
# most kinds, defaults left out
cat >src/scene.yaml <<'EOF'
name: standalone
time: {fps: 24, frames: 2}
wind: {velocity: [0.5, 0, 0], drag: 0.2}
cloths:
  - name: sheet
    grid: {size: [0.8, 0.8], resolution: [8, 8], center: [0, 0.45, 0]}
    material: {density: 0.1}
    pins:
      - grid_points: [[0, 0]]
    scripts:
      - select: {grid_points: [[8, 8]]}
        motion:
          keys:
            - {time: 0}
            - {time: 1, translate: [0, 0.1, 0]}
        release: 0.05
bodies:
  - name: ball
    shape: mesh
    mesh: {file: ball.obj, scale: 0.3}
    friction_keys: [{time: 0, friction: 0.6}, {time: 1, friction: 0.2}]
  - shape: plane
    normal: [0, 1, 0]
EOF
export CLOTHSIM_CACHE="$PWD/cache"

# --- the run, and its folder's scene.yaml and assets
run 0 run src/scene.yaml -q -o part --frames 2
[ -s part/scene.yaml ] || fail "no scene.yaml in the run folder"
grep -q '^  dt: auto$' part/scene.yaml || fail "scene.yaml lacks the default time.dt"
grep -q 'edge_stiffness:' part/scene.yaml || fail "scene.yaml lacks the material's defaults"
grep -q 'name: "body1"' part/scene.yaml || fail "scene.yaml lacks the default body name"
grep -Eq 'file: "assets/[0-9a-f]{16}/ball.obj"' part/scene.yaml ||
    fail "the mesh is not named by its content in scene.yaml"
grep -q 'cache: "assets"' part/scene.yaml || fail "the level sets are not looked for in assets/"
ls part/assets/*/ball.obj >/dev/null 2>&1 || fail "the mesh was not copied into assets/"
ls part/assets/ball-*.vdb >/dev/null 2>&1 || fail "the level set was not copied into assets/"
cmp -s src/ball.obj part/assets/*/ball.obj || fail "the copied mesh differs"

# --- the resolved scene runs the same bits, and resolves to itself
run 0 run part/scene.yaml -q -o again
[ "$(hashes part)" = "$(hashes again)" ] || fail "run DIR/scene.yaml gave other state hashes"
cmp -s part/scene.yaml again/scene.yaml || fail "the resolved scene does not resolve to itself"
err_has "read from the cache part/assets/ball-"

# --- the reference, never interrupted
run 0 run src/scene.yaml -q -o ref --frames 4

# --- the scene, its mesh and the cache gone: render and resume from DIR
rm -rf src cache again
run 0 render part --engine preview --frames last --size 32x24 --samples 1 -q
[ -s part/images/frame_0002.png ] || fail "render DIR wrote no image"
run 0 run part --frames 4 --resume -q
[ "$(hashes part)" = "$(hashes ref)" ] || fail "the resumed frames differ from the reference's"
k=0
while [ "$k" -le 4 ]; do
    f=frames/$(printf 'frame_%04d' "$k").ply
    cmp -s "part/$f" "ref/$f" || fail "part/$f differs from ref/$f"
    k=$((k + 1))
done
grep -q '^  frames: 4$' part/scene.yaml || fail "scene.yaml does not say the frames resumed to"
# (the resumed run came from part/scene.yaml, which summary.json names)
run 0 info part
grep -q "^run part: scene part/scene.yaml, status ok, 5 frames written" out.txt ||
    fail "info does not read the folder's scene"

# --- refused: another setting than the run's
run 2 run part --frames 5 --resume --set 'gravity=[0,-9,0]'
err_has "the resolved scene differs from the run's: now '.*-9, 0\]', then '.*-9.8, 0\]'"
run 2 run ref/frames --resume
err_has "a folder without scene.yaml"
