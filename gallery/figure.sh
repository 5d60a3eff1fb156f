#!/bin/sh
# gallery/figure.sh NAME [test|gallery] [--copy]: one paper figure from
# nothing -- simulate scenes/figures/NAME.yaml, then ray trace and animate it.
#
#   gallery (default)  the gallery size: the scene's `# gallery:` line (below)
#                      is added to `clothsim run`; the pictures are copied
#                      into gallery/figures/
#   test               the scene as committed (its small test size), fewer
#                      samples; gallery/figures/ is left alone unless --copy
#
# Everything goes to out/figures/NAME/ (removed first):
#   run/              the run (frames/, summary.json, frames.jsonl), run.log
#   stills/           Embree, 1280x720: the key frames and the last frame
#   preview/          OSMesa preview of the last frame, 1280x720 (with the
#                     triangle edges when the cloth has at most 20,000)
#   turntable/        8 views of the last frame, contact_sheet.png,
#                     turntable.mp4/.gif (ffmpeg); left out, with a note,
#                     where an orbiting camera is refused (below a plane)
#   animation/        every frame, animation.mp4 (H.264) and animation.gif at
#                     the scene's frames per second (ffmpeg)
#   compare/, compare_stills/, side_by_side.png
#                     with a comparison (below): the same scene with other
#                     settings, its last frame beside ours (ffmpeg hstack;
#                     without ffmpeg the two stills stay apart)
#   table3.json, table3.md
#                     the figure's row of Table 3: triangles, frames, ranks,
#                     threads, seconds per frame (median and mean), peak
#                     memory of the run, intersecting triangle pairs at the
#                     last frame
#   commands.txt      every command this script ran, in order
# Copied into gallery/figures/ (gallery mode, or test with --copy):
#   NAME.png (last frame), NAME_fNNNN.png (key frames, but those the same
#   picture as the last: the cloth at rest), NAME_preview.png,
#   NAME_turntable.png (contact sheet), NAME.gif (the animation when under
#   FIGURE_GIF_MAX, else animation_small.gif, the same 320 pixels wide at 12
#   frames a second, if that is), NAME_compare.png (or NAME_compare_a.png
#   and _b.png).
#
# What the scene's header comment may say, one line each:
#   # gallery: --set cloths.0.grid.resolution=[224,224]
#         `clothsim run` options for the gallery size (no spaces inside a
#         value). Without the line, the first commented `clothsim run SCENE
#         OPTIONS` line after one saying GALLERY (the figure scenes'
#         "GALLERY size" note) is used, else none.
#   # keyframes: 12,24,36
#         the stills besides the last frame (default: a quarter, half and
#         three quarters of the run); numbers past the last frame are dropped,
#         and `none` asks for none
#   # compare: --set effects.friction=projection
#         a second run with these options, shown beside the first
#         (rolling_cloth compares with the previous friction method, Fig. 7,
#         even without the line); a first word frame=N compares frame N of
#         the two runs instead of their last frames (e.g. where both are still
#         in view), as FIGURE_COMPARE_FRAME=N does, and the second run stops
#         at frame N
#
# Environment: BUILD (default build, a Release build), FIGURE_RESUME=1 (go
# on with an interrupted run in out/figures/NAME/run: `clothsim run
# --resume`, same options; the pictures are all remade), FIGURE_SIM_ONLY=1
# (the run and its Table 3 row, no pictures, nothing copied), FIGURE_RUN_ARGS (more
# `clothsim run` options, e.g. "--frames 12" while developing),
# FIGURE_STILL_SIZE/_SAMPLES, FIGURE_ANIM_SIZE/_SAMPLES (image size and
# samples of the stills and of the animation), FIGURE_RENDER_ARGS (more
# options of the ray-traced renders, e.g. "--threads 1"), FIGURE_GIF_MAX
# (bytes, default 1500000: a larger animation.gif is copied as
# animation_small.gif, 320 pixels wide at 12 frames a second, if that is
# under it).
# Exit status: 0 done; 1 bad command line; else the failing command's.
set -eu
set -f   # options such as resolution=[224,224] are never file patterns
cd "$(dirname "$0")/.."

usage() {
    echo "usage: gallery/figure.sh NAME [test|gallery] [--copy]" >&2
    exit 1
}
[ $# -ge 1 ] || usage
NAME=$1
MODE=gallery
COPY=
shift
for a in "$@"; do
    case $a in
    test | gallery) MODE=$a ;;
    --copy) COPY=1 ;;
    *) usage ;;
    esac
done
[ "$MODE" = gallery ] && COPY=1
case $NAME in
*/* | .* | '') usage ;;
esac

BUILD=${BUILD:-build}
EXE=$BUILD/clothsim
SCENE=scenes/figures/$NAME.yaml
# scenes/NAME.yaml (the drape) serves for trying the pipeline out
[ -f "$SCENE" ] || SCENE=scenes/$NAME.yaml
[ -f "$SCENE" ] || { echo "figure.sh: no scenes/figures/$NAME.yaml" >&2; exit 1; }
[ -x "$EXE" ] || { echo "figure.sh: no $EXE (build first, or set BUILD)" >&2; exit 1; }

if [ "$MODE" = gallery ]; then
    STILL_SIZE=${FIGURE_STILL_SIZE:-1280x720} STILL_SAMPLES=${FIGURE_STILL_SAMPLES:-64}
    ANIM_SIZE=${FIGURE_ANIM_SIZE:-640x360} ANIM_SAMPLES=${FIGURE_ANIM_SAMPLES:-16}
    TURN_SIZE=480x270 TURN_SAMPLES=32
else
    STILL_SIZE=${FIGURE_STILL_SIZE:-1280x720} STILL_SAMPLES=${FIGURE_STILL_SAMPLES:-16}
    ANIM_SIZE=${FIGURE_ANIM_SIZE:-480x270} ANIM_SAMPLES=${FIGURE_ANIM_SAMPLES:-4}
    TURN_SIZE=320x180 TURN_SAMPLES=8
fi

OUT=out/figures/$NAME
LOG=$OUT/commands.txt
# FIGURE_RESUME=1 continues an interrupted run (a gallery size takes hours)
# with `clothsim run --resume` and remakes everything else; the run's peak
# memory is then the resumed process's.
RESUME=
if [ -n "${FIGURE_RESUME:-}" ] && [ -f "$OUT/run/state.h5" ]; then
    RESUME=--resume
    find "$OUT" -mindepth 1 -maxdepth 1 ! -name run ! -name commands.txt -exec rm -rf {} +
else
    rm -rf "$OUT"
    mkdir -p "$OUT"
    : >"$LOG"
fi

# quoted ARGS...: the arguments as a shell reads them back (quoted where needed).
quoted() {
    out=
    for a in "$@"; do
        case $a in
        *[!A-Za-z0-9_./=:,@%+-]* | '')
            a="'$(printf '%s' "$a" | sed "s/'/'\\\\''/g")'" ;;
        esac
        out="$out${out:+ }$a"
    done
    printf '%s\n' "$out"
}

# step CMD...: logs the command to commands.txt and the terminal, runs it.
step() {
    quoted + "$@" | tee -a "$LOG"
    "$@"
}

# What the scene's header says (see above), as shell assignments.
eval "$(python3 - "$SCENE" "$NAME" <<'EOF'
import re, shlex, sys
path, name = sys.argv[1], sys.argv[2]
gallery = fallback = keyframes = compare = None
after_note = False   # past a header line saying GALLERY
for line in open(path):
    if not line.startswith("#"):
        if line.strip():
            break          # the header comment ends at the first YAML line
        continue
    text = line[1:].strip()
    m = re.match(r"(gallery|keyframes|compare):\s*(.*)$", text)
    if m:
        key, value = m.group(1), m.group(2).strip()
        if key == "gallery":
            gallery = value
        elif key == "keyframes":
            keyframes = value
        else:
            compare = value
        continue
    after_note = after_note or "GALLERY" in text
    # the run line of a "GALLERY size" note (the first after it)
    m = re.match(r"clothsim run\s+\S+\s+(.*)$", text)
    if m and fallback is None and after_note:
        fallback = m.group(1).strip()
if gallery is None:
    gallery = fallback or ""
if compare is None and name == "rolling_cloth":
    compare = "--set effects.friction=projection"
compare_frame = ""
if compare:
    m = re.match(r"frame=(\d+)\s*(.*)$", compare)
    if m:
        compare_frame, compare = m.group(1), m.group(2).strip()
for var, value in (("GALLERY_ARGS", gallery), ("KEYFRAMES", keyframes or ""),
                   ("COMPARE_ARGS", compare or ""), ("COMPARE_FRAME", compare_frame)):
    print("%s=%s" % (var, shlex.quote(value)))
EOF
)"
COMPARE_FRAME=${FIGURE_COMPARE_FRAME:-$COMPARE_FRAME}
RARGS=${FIGURE_RENDER_ARGS:-}
GIF_MAX=${FIGURE_GIF_MAX:-1500000}
SIZE_ARGS=
[ "$MODE" = gallery ] && SIZE_ARGS=$GALLERY_ARGS
echo "figure $NAME ($MODE): $SCENE ${SIZE_ARGS:+with $SIZE_ARGS}"

# simulate RUN_DIR ARGS...: clothsim run, its output in RUN_DIR.log and its
# peak memory (the process's maximum resident set) in RUN_DIR.rss (KiB).
# Returns clothsim's exit status.
simulate() {
    dir=$1
    shift
    quoted + "$EXE" run "$SCENE" -o "$dir" "$@" | tee -a "$LOG"
    rc=0
    python3 - "$dir.rss" "$dir.log" "$EXE" run "$SCENE" -o "$dir" "$@" <<'EOF' || rc=$?
import os, subprocess, sys
rss_path, log_path, cmd = sys.argv[1], sys.argv[2], sys.argv[3:]
with open(log_path, "wb") as log:
    proc = subprocess.Popen(cmd, stdin=subprocess.DEVNULL, stdout=log, stderr=subprocess.STDOUT)
    _, status, usage = os.wait4(proc.pid, 0)
    proc.returncode = 0   # reaped here; Popen must not wait again
with open(rss_path, "w") as f:
    f.write("%d\n" % usage.ru_maxrss)
sys.exit(os.waitstatus_to_exitcode(status) & 255)
EOF
    return $rc
}

# shellcheck disable=SC2086
simulate "$OUT/run" $SIZE_ARGS ${FIGURE_RUN_ARGS:-} $RESUME || {
    rc=$?
    tail -n 5 "$OUT/run.log" >&2
    echo "figure.sh: the simulation of $NAME failed (exit $rc)" >&2
    exit $rc
}
tail -n 3 "$OUT/run.log"

# FIGURE_SIM_ONLY=1: the run and its Table 3 row only (no pictures)
if [ -z "${FIGURE_SIM_ONLY:-}" ]; then
# The last frame, the key frames and whether to draw the mesh's edges.
eval "$(python3 - "$OUT/run/summary.json" "$KEYFRAMES" <<'EOF'
import json, sys
s = json.load(open(sys.argv[1]))
last = s["frames_written"] - 1
if sys.argv[2]:
    keys = []
    for item in sys.argv[2].split(","):
        item = item.strip()
        if item.isdigit() and int(item) < last and int(item) not in keys:
            keys.append(int(item))
else:
    keys = sorted({round(last * q) for q in (0.25, 0.5, 0.75)} - {last})
print("LAST=%d" % last)
print("KEYS='%s'" % " ".join(str(k) for k in keys))
print("TRIANGLES=%d" % s["triangles"])
EOF
)"
LIST=
for k in $KEYS; do LIST="$LIST$k,"; done
LIST=${LIST}last
LASTF=$(printf '%04d' "$LAST")

# shellcheck disable=SC2086
step "$EXE" render "$OUT/run" -q --frames "$LIST" --size "$STILL_SIZE" \
    --samples "$STILL_SAMPLES" $RARGS -o "$OUT/stills"
WIRE=
[ "$TRIANGLES" -le 20000 ] && WIRE=--wireframe
step "$EXE" render "$OUT/run" -q --engine preview $WIRE --frames last --size "$STILL_SIZE" \
    --samples 8 -o "$OUT/preview"
# A turntable can fail where the scene cannot be seen all round (an orbiting
# camera below an inclined plane is refused): said, and left out.
# shellcheck disable=SC2086
step "$EXE" render "$OUT/run" -q --frames last --turntable 8 --size "$TURN_SIZE" \
    --samples "$TURN_SAMPLES" $RARGS -o "$OUT/turntable" ||
    echo "figure.sh: no turntable for $NAME (above); going on without it" >&2
# shellcheck disable=SC2086
step "$EXE" render "$OUT/run" -q --animation --size "$ANIM_SIZE" --samples "$ANIM_SAMPLES" \
    $RARGS -o "$OUT/animation"

# A comparison: the same scene with other settings, the last frames side by
# side (left: the scene as written; right: with COMPARE_ARGS).
HAVE_FFMPEG=
command -v ffmpeg >/dev/null 2>&1 && HAVE_FFMPEG=1
if [ -n "$COMPARE_ARGS" ]; then
    crc=0
    # a comparison at frame=N needs only N frames of its run
    CRUN_FRAMES=
    [ -n "$COMPARE_FRAME" ] && CRUN_FRAMES="--frames $COMPARE_FRAME"
    # shellcheck disable=SC2086
    simulate "$OUT/compare" $SIZE_ARGS ${FIGURE_RUN_ARGS:-} $COMPARE_ARGS $CRUN_FRAMES || crc=$?
    if [ "$crc" -ne 0 ] && [ "$crc" -ne 3 ]; then
        tail -n 5 "$OUT/compare.log" >&2
        echo "figure.sh: the comparison run ($COMPARE_ARGS) failed (exit $crc)" >&2
        exit $crc
    fi
    # an unstable comparison (exit 3) kept the frames before; show its last
    [ "$crc" -eq 3 ] && echo "figure.sh: the comparison run became unstable:" \
        "$(tail -n 1 "$OUT/compare.log")" >&2
    # the frame compared: the last of each run, or frame=N of both
    CFRAMES=last
    ASTILL=$OUT/stills/frame_$LASTF.png
    ATEXT=
    if [ -n "$COMPARE_FRAME" ]; then
        CFRAMES=$COMPARE_FRAME
        ATEXT=", frame $COMPARE_FRAME"
        # shellcheck disable=SC2086
        step "$EXE" render "$OUT/run" -q --frames "$CFRAMES" --size "$STILL_SIZE" \
            --samples "$STILL_SAMPLES" $RARGS -o "$OUT/compare_ours"
        ASTILL=$OUT/compare_ours/frame_$(printf '%04d' "$COMPARE_FRAME").png
    fi
    # shellcheck disable=SC2086
    step "$EXE" render "$OUT/compare" -q --frames "$CFRAMES" --size "$STILL_SIZE" \
        --samples "$STILL_SAMPLES" $RARGS -o "$OUT/compare_stills"
    set +f
    CSTILL=$(ls "$OUT"/compare_stills/frame_*.png | tail -n 1)
    set -f
    if [ -n "$HAVE_FFMPEG" ]; then
        # labels where ffmpeg can draw text with a font we know of
        FONT=/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf
        # (quotes, backslashes and % would need ffmpeg's escaping: dropped)
        right=$(echo "$COMPARE_ARGS" | sed 's/--set //g' | tr -d "'\\\\%")
        label() {
            printf "drawtext=fontfile=%s:text='%s':x=24:y=24:fontsize=36:fontcolor=white:%s" \
                "$FONT" "$1" "box=1:boxcolor=black@0.5:boxborderw=8"
        }
        FILTER="[0:v]$(label "as written$ATEXT")[a];[1:v]$(label "$right$ATEXT")[b];[a][b]hstack=inputs=2"
        [ -f "$FONT" ] || FILTER="[0:v][1:v]hstack=inputs=2"
        step ffmpeg -nostdin -v error -y -i "$ASTILL" -i "$CSTILL" \
            -filter_complex "$FILTER" "$OUT/side_by_side.png" ||
            step ffmpeg -nostdin -v error -y -i "$ASTILL" -i "$CSTILL" \
                -filter_complex "[0:v][1:v]hstack=inputs=2" "$OUT/side_by_side.png"
    else
        echo "figure.sh: ffmpeg is not installed: the two stills are $ASTILL" \
            "and $CSTILL (no side-by-side picture)" >&2
    fi
fi

fi # FIGURE_SIM_ONLY

# Table 3's row.
python3 - "$OUT" "$NAME" "$MODE" "$SCENE" "$EXE" <<'EOF'
import json, os, statistics, subprocess, sys
out, name, mode, scene, exe = sys.argv[1:6]
s = json.load(open(os.path.join(out, "run", "summary.json")))
frames = s.get("frames") or []
sim = [f for f in frames if f.get("frame", 0) > 0]
secs = [f["seconds"] for f in sim if "seconds" in f]
rss_kib = int(open(os.path.join(out, "run.rss")).read())
pairs = sim[-1].get("intersections") if sim else None
pairs_by = "verifier, every frame (self_collision.verify)" if pairs is not None else None
if pairs is None and s.get("format") == "ply":
    # the verifier after the fact, on the last frame's file
    last = os.path.join(out, "run", "frames", "frame_%04d.ply" % (s["frames_written"] - 1))
    if os.path.exists(last):
        r = subprocess.run([exe, "intersections", last], capture_output=True, text=True)
        if r.returncode in (0, 1) and r.stdout.split():
            pairs = int(r.stdout.split()[0])
            pairs_by = "clothsim intersections on the last frame"
row = {
    "figure": name,
    "mode": mode,
    "scene": scene,
    "overrides": s.get("overrides", []),
    "status": s.get("status"),
    "particles": s.get("particles"),
    "triangles": s.get("triangles"),
    "frames": len(sim),
    "fps": s.get("fps"),
    "ranks": s.get("ranks", 1),
    "threads": s.get("threads", 1),
    "seconds_per_frame_median": statistics.median(secs) if secs else None,
    "seconds_per_frame_mean": statistics.fmean(secs) if secs else None,
    "simulation_seconds": s.get("simulation_seconds"),
    "peak_memory_mib": round(rss_kib / 1024.0, 1),
    "intersecting_pairs_end": pairs,
    "intersecting_pairs_by": pairs_by,
}
with open(os.path.join(out, "table3.json"), "w") as f:
    json.dump(row, f, indent=2)
    f.write("\n")
fmt = lambda v, p="%.3g": "—" if v is None else (p % v)
md = ("| %s | %s | %s | %d | %d | %d | %s | %s | %s | %s |\n" % (
    name, mode, "{:,}".format(row["triangles"]), row["frames"], row["ranks"], row["threads"],
    fmt(row["seconds_per_frame_median"]), fmt(row["seconds_per_frame_mean"]),
    fmt(row["peak_memory_mib"], "%.0f"), fmt(pairs, "%d")))
with open(os.path.join(out, "table3.md"), "w") as f:
    f.write("| figure | size | triangles | frames | ranks | threads | s/frame (median) "
            "| s/frame (mean) | peak MiB | intersecting pairs, last frame |\n")
    f.write("|---|---|---|---|---|---|---|---|---|---|\n")
    f.write(md)
print("table 3: " + md.strip())
EOF

if [ -n "$COPY" ] && [ -z "${FIGURE_SIM_ONLY:-}" ]; then
    G=gallery/figures
    mkdir -p "$G"
    set +f
    rm -f "$G/$NAME.png" "$G/$NAME.gif" "$G/$NAME"_f[0-9]*.png "$G/${NAME}_preview.png" \
        "$G/${NAME}_turntable.png" "$G/${NAME}_compare.png" "$G/${NAME}_compare_a.png" \
        "$G/${NAME}_compare_b.png"
    set -f
    step cp "$OUT/stills/frame_$LASTF.png" "$G/$NAME.png"
    for k in $KEYS; do
        f=$(printf '%04d' "$k")
        # a key frame the same as the last (the cloth has come to rest) is not copied
        cmp -s "$OUT/stills/frame_$f.png" "$OUT/stills/frame_$LASTF.png" ||
            step cp "$OUT/stills/frame_$f.png" "$G/${NAME}_f$f.png"
    done
    step cp "$OUT/preview/frame_$LASTF.png" "$G/${NAME}_preview.png"
    if [ -f "$OUT/turntable/contact_sheet.png" ]; then
        step cp "$OUT/turntable/contact_sheet.png" "$G/${NAME}_turntable.png"
    fi
    # The GIF when under GIF_MAX bytes; else one 320 pixels wide at 12
    # frames a second made from it.
    GIF=$OUT/animation/animation.gif
    if [ -f "$GIF" ] && [ "$(wc -c <"$GIF")" -ge "$GIF_MAX" ]; then
        step ffmpeg -nostdin -v error -y -i "$GIF" \
            -vf "fps=12,scale=320:-2:flags=lanczos,split[a][b];[a]palettegen[p];[b][p]paletteuse" \
            "$OUT/animation/animation_small.gif" || true
        GIF=$OUT/animation/animation_small.gif
    fi
    if [ -f "$GIF" ]; then
        bytes=$(wc -c <"$GIF")
        if [ "$bytes" -lt "$GIF_MAX" ]; then
            step cp "$GIF" "$G/$NAME.gif"
        else
            echo "figure.sh: $GIF is $bytes bytes, not copied ($GIF_MAX at most)"
        fi
    fi
    if [ -f "$OUT/side_by_side.png" ]; then
        step cp "$OUT/side_by_side.png" "$G/${NAME}_compare.png"
    elif [ -n "$COMPARE_ARGS" ]; then
        step cp "$ASTILL" "$G/${NAME}_compare_a.png"
        step cp "$CSTILL" "$G/${NAME}_compare_b.png"
    fi
fi
echo "figure $NAME: done, in $OUT"
