#!/bin/sh
# cli_animation.sh CLOTHSIM_EXE SOURCE_DIR: `clothsim render --animation`
# assembles the rendered frames into animation.mp4 (H.264, yuv420p, even
# sides) and animation.gif at the scene's frame rate through the ffmpeg
# program; without ffmpeg the PNG frames remain with a one-line note (exit
# 0); a failing ffmpeg is exit 4 with its message, the frames kept. The
# checks that need the real ffmpeg (and ffprobe) run when it is installed
# (scripts/install-deps.sh installs it); stand-ins check the rest anyway.
set -eu

NAME=cli_animation
. "$2/tests/harness.sh"

# frames_of FILE: the number of video frames ffprobe decodes in FILE.
frames_of() {
    ffprobe -v error -count_frames -select_streams v:0 \
        -show_entries stream=nb_read_frames -of default=nw=1:nk=1 "$1"
}

# probe FILE ENTRY: one stream entry (codec_name, pix_fmt, width, ...).
probe() {
    ffprobe -v error -select_streams v:0 -show_entries "stream=$2" \
        -of default=nw=1:nk=1 "$1"
}

cat >tiny.yaml <<'EOF'
# A 6x6 sheet over a small ball on the ground, 12 frames a second.
cloths: [{name: sheet, grid: {size: [1, 1], resolution: [6, 6], center: [0, 0.5, 0]}}]
bodies:
  - {name: ball, shape: sphere, radius: 0.2, position: [0, 0.2, 0]}
  - {name: ground, shape: plane}
time: {frames: 3, fps: 12}
EOF

# A folder without ffmpeg: the PATH of the runs that must do without it.
mkdir noffmpeg

# --- help
run 0 help render
grep -q -- '--animation' out.txt || fail "'help render' does not explain --animation"
grep -q 'animation.mp4' out.txt || fail "'help render' does not name animation.mp4"

run 0 run tiny.yaml -q -o sim

# --- stand-in ffmpeg: what it is asked for (every run: the real one below
# only runs where ffmpeg is installed)
mkdir fake
cat >fake/ffmpeg <<'EOF'
#!/bin/sh
echo "$@" >>"$FFMPEG_ARGS"
for last; do :; done
echo fake >"$last"
EOF
chmod +x fake/ffmpeg
FFMPEG_ARGS=$PWD/args.txt PATH="$PWD/fake:$PATH" \
    run 0 render sim --animation --size 41x31 --samples 1 -o fakeout
for k in 0 1 2 3; do
    [ -s "fakeout/frame_000$k.png" ] || fail "frame $k was not rendered"
done
[ -s fakeout/animation.mp4 ] || fail "no animation.mp4 from the stand-in"
[ -s fakeout/animation.gif ] || fail "no animation.gif from the stand-in"
grep -q 'animation: fakeout/animation.mp4' out.txt || fail "the animation is not reported"
[ "$(wc -l <args.txt)" -eq 2 ] || fail "ffmpeg should run twice (MP4, GIF)"
mp4_args=$(sed -n 1p args.txt)
gif_args=$(sed -n 2p args.txt)
for want in '-framerate 12 ' '-start_number 0 ' 'frame_%04d.png' '-frames:v 4 ' \
            'libx264' 'yuv420p' 'ceil(iw/2)\*2'; do
    echo "$mp4_args" | grep -q -- "$want" || fail "MP4: ffmpeg not given '$want': $mp4_args"
done
for want in '-framerate 12 ' 'palettegen' 'paletteuse' '-frames:v 4 '; do
    echo "$gif_args" | grep -q -- "$want" || fail "GIF: ffmpeg not given '$want': $gif_args"
done
for f in fakeout/*.tmp; do [ ! -e "$f" ] || fail "a temporary file $f was left"; done
# a range starts where it starts
rm args.txt
FFMPEG_ARGS=$PWD/args.txt PATH="$PWD/fake:$PATH" \
    run 0 render sim --animation --frames 2-3 --size 41x31 --samples 1 -o fakeout -q
grep -q -- '-start_number 2 .*-frames:v 2 ' args.txt || fail "frames 2-3: $(cat args.txt)"

# --- a failing ffmpeg: exit 4 with its message, the frames kept, no animation
cat >fake/ffmpeg <<'EOF'
#!/bin/sh
for last; do :; done
echo partial >"$last"
echo "ffmpeg: Unknown encoder 'libx264'" >&2
exit 1
EOF
PATH="$PWD/fake:$PATH" run 4 render sim --animation --size 41x31 --samples 1 -o fakeout -q
err_has "Unknown encoder"
err_has "animation.mp4: ffmpeg failed \\(exit status 1\\)"
err_has "images are kept"
for k in 0 1 2 3; do
    [ -s "fakeout/frame_000$k.png" ] || fail "frame $k was not kept after ffmpeg failed"
done
[ ! -e fakeout/animation.mp4 ] || fail "a failed animation.mp4 was left"
[ ! -e fakeout/animation.gif ] || fail "an earlier animation.gif was left beside a failed one"
for f in fakeout/*.tmp; do [ ! -e "$f" ] || fail "a temporary file $f was left"; done

# --- without ffmpeg: the PNG frames and a note, exit 0; an earlier
# animation in the folder is removed, not passed off as this one
echo old >fakeout/animation.gif
PATH="$PWD/noffmpeg" run 0 render sim --animation --size 41x31 --samples 1 -o fakeout -q
for k in 0 1 2 3; do
    [ -s "fakeout/frame_000$k.png" ] || fail "frame $k missing without ffmpeg"
done
err_has "no animation: ffmpeg is not installed"
[ "$(wc -l <err.txt)" -eq 1 ] || fail "the note is not one line"
[ ! -e fakeout/animation.mp4 ] || fail "an animation.mp4 without ffmpeg?"
[ ! -e fakeout/animation.gif ] || fail "the old animation.gif was left without ffmpeg"
# the default folder is RUN/images
PATH="$PWD/noffmpeg" run 0 render sim --animation --frames last --size 20x16 --samples 1 -q
[ -s sim/images/frame_0003.png ] || fail "no sim/images/frame_0003.png"
err_has "1 PNG frame is in sim/images"

# --- bad command line
run 1 render sim --animation --turntable 3
err_has "do not go together"

# --- the real ffmpeg, where installed
if command -v ffmpeg >/dev/null 2>&1; then
    run 0 render sim --animation --size 41x31 --samples 1
    for f in sim/images/animation.mp4 sim/images/animation.gif; do
        [ -s "$f" ] || fail "no $f"
    done
    if command -v ffprobe >/dev/null 2>&1; then
        [ "$(frames_of sim/images/animation.mp4)" = 4 ] ||
            fail "animation.mp4 has $(frames_of sim/images/animation.mp4) frames, expected 4"
        [ "$(frames_of sim/images/animation.gif)" = 4 ] ||
            fail "animation.gif has $(frames_of sim/images/animation.gif) frames, expected 4"
        [ "$(probe sim/images/animation.mp4 codec_name)" = h264 ] || fail "MP4 is not H.264"
        [ "$(probe sim/images/animation.mp4 pix_fmt)" = yuv420p ] || fail "MP4 is not yuv420p"
        [ "$(probe sim/images/animation.mp4 width)x$(probe sim/images/animation.mp4 height)" \
            = 42x32 ] || fail "MP4 sides are not padded to even"
        [ "$(probe sim/images/animation.mp4 r_frame_rate)" = 12/1 ] ||
            fail "MP4 is not at the scene's 12 frames a second"
        # frames not one after another: in the order listed
        run 0 render sim --animation --frames 3,0,2 --size 32x24 --samples 1 -o some -q
        [ "$(frames_of some/animation.mp4)" = 3 ] || fail "--frames 3,0,2: not 3 frames"
        [ "$(frames_of some/animation.gif)" = 3 ] || fail "--frames 3,0,2: GIF not 3 frames"
        for f in some/.animation*; do [ ! -e "$f" ] || fail "the frame links $f were left"; done
        # a turntable makes its animations through the same code
        run 0 render sim --turntable 3 --size 32x24 --samples 1 -q
        [ "$(frames_of sim/turntable/turntable.mp4)" = 3 ] || fail "turntable.mp4: not 3 frames"
        [ "$(frames_of sim/turntable/turntable.gif)" = 3 ] || fail "turntable.gif: not 3 frames"
    fi
else
    echo "cli_animation: ffmpeg is not installed: the real-ffmpeg checks were skipped"
fi

echo "cli_animation: all checks passed"
