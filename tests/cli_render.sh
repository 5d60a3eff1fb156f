#!/bin/sh
# cli_render.sh CLOTHSIM_EXE SOURCE_DIR: `clothsim run --render` and
# `clothsim render` write the images they promise, turntables and contact
# sheets included, the same bytes twice, and refuse bad input (status 2,
# one clear line) rather than crash or write a black image.
set -eu

NAME=cli_render
. "$2/tests/harness.sh"

# png_size FILE: prints WIDTHxHEIGHT of a PNG, or fails the test.
png_size() {
    python3 - "$1" <<'EOF' || fail "$1 is not a PNG"
import struct, sys
data = open(sys.argv[1], "rb").read(24)
if data[:8] != b"\x89PNG\r\n\x1a\n" or data[12:16] != b"IHDR":
    sys.exit(1)
w, h = struct.unpack(">II", data[16:24])
print("%dx%d" % (w, h))
EOF
}

# check_png FILE WxH
check_png() {
    [ -s "$1" ] || fail "missing or empty $1"
    size=$(png_size "$1")
    [ "$size" = "$2" ] || fail "$1 is $size, expected $2"
}

cat >tiny.yaml <<'EOF'
# A 6x6 sheet over a small ball on the ground.
cloths: [{name: sheet, grid: {size: [1, 1], resolution: [6, 6], center: [0, 0.5, 0]}}]
bodies:
  - {name: ball, shape: sphere, radius: 0.2, position: [0, 0.2, 0]}
  - {name: ground, shape: plane}
time: {frames: 2}
EOF

# --- help
run 0 help render
for opt in --engine --frames --size --samples --turntable --output --set; do
    grep -q -- "$opt" out.txt || fail "'help render' does not explain $opt"
done
run 0 --help
grep -q 'render' out.txt || fail "--help does not mention render"
run 0 run --help
grep -q -- '--render' out.txt || fail "'run --help' does not explain --render"

# --- run --render: an image per frame beside the frames
run 0 run tiny.yaml -q -o sim --render preview --size 64x48 --set 'cloths.0.color=[0.1,0.3,0.9]'
for k in 0 1 2; do
    check_png "sim/images/frame_000$k.png" 64x48
done
python3 - sim/summary.json <<'EOF' || fail "summary.json does not record the overrides"
import json, sys
s = json.load(open(sys.argv[1]))
assert s["overrides"] == ["cloths.0.color=[0.1,0.3,0.9]"], s.get("overrides")
EOF

# --- render a run folder: every frame by default, ray traced
run 0 render sim --size 80x60 --samples 2
for k in 0 1 2; do
    check_png "sim/images/frame_000$k.png" 80x60
done
grep -q 'rendered 3 images' out.txt || fail "no summary line"

# --- the same frame twice: the same bytes
run 0 render sim --frames last --size 48x36 --samples 3 -o again1 -q
run 0 render sim --frames 2 --size 48x36 --samples 3 -o again2 -q
[ ! -s out.txt ] || fail "--quiet still printed"
cmp -s again1/frame_0002.png again2/frame_0002.png || fail "two renders of a frame differ"
[ ! -e again1/frame_0000.png ] || fail "--frames last rendered frame 0"

# --- preview options and frame lists
run 0 render sim -e preview --wireframe --flat --frames 0,2 --size 40x30 -o pv -q
check_png pv/frame_0000.png 40x30
check_png pv/frame_0002.png 40x30
[ ! -e pv/frame_0001.png ] || fail "--frames 0,2 rendered frame 1"

# --- two cloths: each read back by its name (OBJ and glb: an object per
# cloth; PLY: a file per cloth), never guessed
cat >two.yaml <<'EOF2'
cloths:
  - {name: a, grid: {size: [0.4, 0.4], resolution: [3, 3], center: [-0.3, 0.5, 0]}}
  - {name: b, grid: {size: [0.4, 0.4], resolution: [2, 4], center: [0.3, 0.5, 0]}}
bodies: [{shape: box, size: [0.3, 0.3, 0.3], position: [0.3, 0.15, 0]}, {shape: plane}]
time: {frames: 1}
EOF2
run 0 run two.yaml -q -o two --format obj
run 0 render two --size 40x30 --samples 1
check_png two/images/frame_0001.png 40x30
if grep -q 'one mesh' err.txt; then
    fail "an OBJ frame of two cloths was drawn as one mesh"
fi
run 0 run two.yaml -q -o twoglb --format glb
run 0 render twoglb --size 40x30 --samples 1 --frames last
check_png twoglb/images/frame_0001.png 40x30
! grep -q 'one mesh' err.txt || fail "a glb frame of two cloths was drawn as one mesh"
run 0 run two.yaml -q -o twoply
for f in frame_0000.a.ply frame_0000.b.ply frame_0001.a.ply frame_0001.b.ply; do
    [ -s "twoply/frames/$f" ] || fail "twoply/frames/$f: no file per cloth"
done
[ ! -e twoply/frames/frame_0001.ply ] || fail "a PLY frame of two cloths was merged"
run 0 render twoply --size 40x30 --samples 1
check_png twoply/images/frame_0001.png 40x30
# cloths renamed since the run: no object of their names, drawn as one mesh
run 0 render two --size 40x30 --samples 1 --frames 1 --set cloths.0.name=c --set cloths.1.name=d
err_has "all cloth is drawn as one mesh"
# a cloth's file missing
rm twoply/frames/frame_0001.b.ply
run 2 render twoply --frames 1 --size 40x30 --samples 1
err_has "frame_0001.b.ply: no such frame file"

# --- a scene file: its initial state
run 0 render tiny.yaml --size 32x24 --samples 1 -q
check_png out/tiny/images/frame_0000.png 32x24

# --- turntable of one frame, with a contact sheet
run 0 render sim --turntable 4 --size 40x30 --samples 1 -e embree -q
for k in 0 1 2 3; do
    check_png "sim/turntable/view_00$k.png" 40x30
done
[ -s sim/turntable/contact_sheet.png ] || fail "no contact sheet"
png_size sim/turntable/contact_sheet.png >/dev/null
if ! command -v ffmpeg >/dev/null 2>&1; then
    [ ! -e sim/turntable/turntable.gif ] || fail "an animation without ffmpeg?"
fi
# A smaller turntable replaces the views; with an ffmpeg on the PATH (a
# stand-in here) it is asked for the animation of exactly these views.
mkdir bin
cat >bin/ffmpeg <<'EOF2'
#!/bin/sh
echo "$@" >ffmpeg_args.txt
for last; do :; done
echo GIF89a >"$last"
EOF2
chmod +x bin/ffmpeg
PATH="$PWD/bin:$PATH" run 0 render sim --turntable 2 --size 40x30 --samples 1 -q
[ ! -e sim/turntable/view_002.png ] || fail "views of the earlier turntable were left"
[ -s sim/turntable/turntable.gif ] || fail "no animation although ffmpeg is there"
grep -q 'view_%03d.png' ffmpeg_args.txt || fail "ffmpeg was not given the views"

# --- bad command lines: status 1
run 1 render
run 1 render sim --engine povray
err_has "not one of embree, preview"
run 1 render sim --size big
err_has "WIDTHxHEIGHT"
run 1 render sim --turntable 4 --frames 0-2
err_has "one frame"
run 1 run tiny.yaml --size 64x48
err_has "go with --render"

# --- bad input: status 2 and a message, no image
run 2 render sim --size 0x0
err_has "1 to 16384"
run 2 render sim --size 100000x100
err_has "1 to 16384"
run 2 render sim --samples 0
err_has "out of range"
run 2 render sim --frames 99
err_has "frame 99 does not exist"
run 2 render tiny.yaml --frames 3
err_has "initial state"
run 2 render no_such_dir
err_has "No such file"
mkdir empty
run 2 render empty
err_has "no summary.json"
cp -r sim gone
rm gone/frames/frame_0001.ply
run 2 render gone --frames 1
err_has "frame_0001.ply: no such frame file"
# a frame file with vertices but no triangles
cat >gone/frames/frame_0001.ply <<'EOF'
ply
format ascii 1.0
element vertex 3
property float x
property float y
property float z
end_header
0 0 0
1 0 0
0 1 0
EOF
run 2 render gone --frames 1
err_has "no triangles"
# a cloth without triangles is a set of particles: nothing to render
cat >dots.yaml <<'EOF'
cloths: [{mesh: {vertices: [[0, 1, 0], [0.1, 1, 0]]}}]
EOF
run 2 render dots.yaml
err_has "no triangles"
# cameras inside a body, below the ground, looking at nothing
run 2 render sim --frames 0 --set 'camera={position: [0, 0.2, 0.05], target: [1, 0.2, 0]}'
err_has "inside body 'ball'"
run 2 render sim --frames 0 --set 'camera={position: [0, -1, 3], target: [0, 0, 0]}'
err_has "below the plane of body 'ground'"
run 2 render sim --frames 0 --set 'camera={position: [0, 3, 0], target: [0, 5, 0], up: [1, 0, 0]}'
err_has "sees nothing"
[ ! -e sim/images/frame_0000.png.tmp ] || fail "a half-written image was left"
# a camera carried by camera.motion: at frame 0 where the scene puts it, by
# frame 2 (t = 0.083 s) turned 170 degrees about x around its target, under
# the ground; the images are drawn from where the motion has taken it
TURN='camera={position: [0, 1, 3], target: [0, 0.4, 0], motion: {keys: [{time: 0}, {time: 0.05, rotate: [170, 0, 0]}]}}'
run 0 render sim --frames 0 --size 40x30 --samples 1 -q -o moving --set "$TURN"
check_png moving/frame_0000.png 40x30
run 2 render sim --frames 2 --size 40x30 --samples 1 -q -o moving --set "$TURN"
err_has "below the plane of body 'ground'"
# a camera the motion tilts 40 degrees down still orbits level in a
# turntable (about the scene's up, not its own tilted one, which took the
# far views under the ground)
TILT='camera={position: [0, 1, 3], target: [0, 0.4, 0], motion: {keys: [{time: 0, rotate: [-40, 0, 0]}]}}'
run 0 render sim --frames 0 --turntable 4 --size 40x30 --samples 1 -q -o tilted --set "$TILT"
check_png tilted/view_002.png 40x30
# run --render finds a bad camera before simulating
run 2 run tiny.yaml -q -o blind --render embree --set 'camera={position: [0, 3, 0], target: [0, 5, 0], up: [1, 0, 0]}'
err_has "sees nothing"
[ ! -e blind/frames ] || fail "run --render simulated with a camera that sees nothing"

echo "cli_render: all checks passed"
