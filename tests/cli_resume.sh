#!/bin/sh
# cli_resume.sh CLOTHSIM_EXE SOURCE_DIR: `clothsim run --resume` continues a
# run stopped by --frames K or by kill -9 into frames byte-identical to a
# run never interrupted, with the same state hashes and the summary carried
# on; a changed scene, changed overrides or another format are refused
# (exit 2) with the difference named.
set -eu

NAME=cli_resume
. "$2/tests/harness.sh"
SRC=$2

# same_frames A B N: frames 0..N of A and B are the same bytes (a file per
# frame, or per cloth of a frame when there are several), and their
# records the same state hashes and counters (not the wall seconds).
same_frames() {
    k=0
    while [ "$k" -le "$3" ]; do
        files=$(cd "$1" && ls frames/$(printf 'frame_%04d' "$k").*ply 2>/dev/null || true)
        [ -n "$files" ] || fail "$1/frames: frame $k missing"
        for f in $files; do
            cmp -s "$1/$f" "$2/$f" || fail "$1/$f and $2/$f differ"
        done
        k=$((k + 1))
    done
    python3 - "$1" "$2" "$3" <<'EOF' || fail "summaries of $1 and $2 disagree"
import json, sys
a, b, n = sys.argv[1], sys.argv[2], int(sys.argv[3])
sa, sb = (json.load(open(d + "/summary.json")) for d in (a, b))
for s, d in ((sa, a), (sb, b)):
    assert s["status"] == "ok", (d, s["status"])
    assert s["frames_written"] == n + 1, (d, s["frames_written"])
    assert [f["frame"] for f in s["frames"]] == list(range(1, n + 1)), (d, len(s["frames"]))
    recs = [json.loads(l) for l in open(d + "/frames.jsonl")]
    assert [r["state_hash"] for r in recs] == [f["state_hash"] for f in s["frames"]], d
    # the stage table counts every frame's steps, a resumed run's too
    calls = {x["name"]: x["calls"] for x in s["stages"]}
    steps = sum(f["steps"] for f in s["frames"])
    assert calls["velocity_half"] == steps, (d, calls["velocity_half"], steps)
assert sa["initial_state_hash"] == sb["initial_state_hash"]
for fa, fb in zip(sa["frames"], sb["frames"]):
    for key in fa:
        if key != "seconds":
            assert fa[key] == fb[key], (fa["frame"], key, fa[key], fb[key])
assert all(len(f["state_hash"]) == 32 for f in sa["frames"])
assert len(set(f["state_hash"] for f in sa["frames"])) == n, "hashes repeat: not of the state"
EOF
}

MPIEXEC=${MPIEXEC:-mpirun}

# mpi_run (harness.sh) without leak checks: Open MPI's own allocations
# need slow unwinding to be told from ours (tests/lsan-mpi.supp), which
# doubles the time; cli_mpi checks leaks under mpirun, and every path here
# runs leak-checked on one rank.
MPI_ASAN_OPTIONS=detect_leaks=0

DRAPE="$SRC/scenes/drape.yaml"
SMALL="cloths.0.grid.resolution=[16,16]"

# --- the run never interrupted: 10 frames (the sheet meets the ball in
# frame 6: contacts and CG work, so the warm starts matter from there)
run 0 run "$DRAPE" -q -o ref --set "$SMALL" --frames 10
[ -s ref/state.h5 ] || fail "no state.h5 after a run"
head -c 8 ref/state.h5 | od -c | grep -q 'H   D   F' || fail "state.h5 is not HDF5"

# --- --frames 7, then --resume to 10
run 0 run "$DRAPE" -q -o part --set "$SMALL" --frames 7
python3 -c '
import json, sys
s = json.load(open("part/summary.json"))
sys.exit(0 if s["frames"][-1]["cg_iterations"] > 0 else "no CG work in frame 7: a weak test")
' || fail "frame 7 of the drape should have CG work"
run 0 run "$DRAPE" -q -o part --set "$SMALL" --frames 10 --resume
same_frames ref part 10
python3 -c '
import json, sys
s = json.load(open("part/summary.json"))
sys.exit(0 if s["resumed_from_frame"] == 7 else "resumed_from_frame %r" % s.get("resumed_from_frame"))
' || fail "the summary does not say where the run resumed"
# resuming a finished run has nothing to do and changes nothing
run 0 run "$DRAPE" -q -o part --set "$SMALL" --frames 10 --resume
same_frames ref part 10
# past the frames asked for: refused
run 2 run "$DRAPE" -q -o part --set "$SMALL" --frames 4 --resume
err_has "frame 10, past the 4 frames"

# --- kill -9 mid-run: summary says "running"; --resume finishes it the same
"$EXE" run "$DRAPE" -q -o killed --set "$SMALL" --frames 400 >/dev/null 2>&1 &
pid=$!
tries=0
while [ ! -e killed/frames/frame_0006.ply ] && [ "$tries" -lt 1200 ]; do
    sleep 0.05
    tries=$((tries + 1))
done
kill -KILL "$pid"
wait "$pid" 2>/dev/null || true
[ -e killed/frames/frame_0006.ply ] || fail "the run to kill wrote no frame 6"
python3 -c '
import json; s = json.load(open("killed/summary.json"))
assert s["status"] == "running", s["status"]
assert "frames" not in s, "a running summary carries the records"
' || fail "after kill -9 the summary should say running"
# the state is of the last record's frame or the one before: on to 10, or
# 2 past it if the kill came late
n=$(($(grep -c . killed/frames.jsonl) + 2))
[ "$n" -ge 10 ] || n=10
run 0 run "$DRAPE" -o killed --set "$SMALL" --frames "$n" --resume
err_has "resuming killed after frame [0-9]+"
# the progress counts this process's frames: its first line is the frame
# after the resumed one (it once showed that frame at "0 s/frame", and a
# rate divided by every frame since the start)
k=$(sed -n 's/.*resuming killed after frame \([0-9]*\).*/\1/p' err.txt)
first=$(grep -m1 -o "^frame [0-9]*/" err.txt || true)
[ "$first" = "frame $((k + 1))/" ] || fail "the resumed progress starts with '$first', expected frame $((k + 1))"
if [ "$n" -gt 10 ]; then
    run 0 run "$DRAPE" -q -o ref --set "$SMALL" --frames "$n"
fi
same_frames ref killed "$n"

# --- self-collision (stack): state of steps A/C carried across the resume
STACK="$SRC/scenes/stack.yaml"
run 0 run "$STACK" -q -o sref --frames 4
run 0 run "$STACK" -q -o spart --frames 2
run 0 run "$STACK" -q -o spart --frames 4 --resume
same_frames sref spart 4

# --- two ranks: rank 0 gathers the state, every rank takes it back
mpi_run 0 2 run "$DRAPE" -q -o mref --set "$SMALL" --frames 8
mpi_run 0 2 run "$DRAPE" -q -o mpart --set "$SMALL" --frames 7
mpi_run 0 2 run "$DRAPE" -q -o mpart --set "$SMALL" --frames 8 --resume
same_frames mref mpart 8
python3 -c 'import json; assert json.load(open("mpart/summary.json"))["ranks"] == 2' ||
    fail "the resumed run did not run on two ranks"

# --- refusals: exit 2, the difference named
cp "$DRAPE" scene.yaml
run 0 run scene.yaml -q -o changed --set "$SMALL" --frames 2
sed 's/radius: 0.35/radius: 0.36/' scene.yaml >scene2.yaml && mv scene2.yaml scene.yaml
run 2 run scene.yaml -q -o changed --set "$SMALL" --frames 3 --resume
err_has "scene.yaml:[0-9]+: the scene file changed"
err_has "now '.*radius: 0.36', then '.*radius: 0.35'"
cp "$DRAPE" scene.yaml
run 2 run scene.yaml -q -o changed --frames 3 --resume
err_has "began with --set cloths.0.grid.resolution=\[16,16\], which is not given now"
run 2 run scene.yaml -q -o changed --set "$SMALL" --set gravity=[0,-9,0] --frames 3 --resume
err_has "--set gravity=\[0,-9,0\] was not given when the run began"
run 2 run scene.yaml -q -o changed --set "$SMALL" --format obj --frames 3 --resume
err_has "the frames are ply files, not obj"
run 2 run scene.yaml -q -o nothing --set "$SMALL" --frames 3 --resume
err_has "there is no nothing/state.h5"
# refusals changed nothing: the run still resumes
run 0 run scene.yaml -q -o changed --set "$SMALL" --frames 3 --resume
[ -f changed/frames/frame_0003.ply ] || fail "no frame 3 after the refusals"

# a body's mesh file changed under the same scene text (the level set far
# above the cloth reads only its band, so the body's mesh itself is hashed)
cat >box.obj <<'EOF'
v -0.3 0 -0.3
v 0.3 0 -0.3
v 0.3 0 0.3
v -0.3 0 0.3
v -0.3 0.5 -0.3
v 0.3 0.5 -0.3
v 0.3 0.5 0.3
v -0.3 0.5 0.3
f 1 3 2
f 1 4 3
f 5 6 7
f 5 7 8
f 1 2 6
f 1 6 5
f 2 3 7
f 2 7 6
f 3 4 8
f 3 8 7
f 4 1 5
f 4 5 8
EOF
cat >boxed.yaml <<'EOF'
cloths: [{grid: {size: [1, 1], resolution: [8, 8], center: [0, 0.8, 0]}}]
bodies: [{shape: mesh, mesh: {file: box.obj}}]
EOF
run 0 run boxed.yaml -q -o boxed --frames 1
sed 's/^v -0.3 0.5 -0.3$/v -0.3 0.6 -0.3/' box.obj >box2.obj && mv box2.obj box.obj
run 2 run boxed.yaml -q -o boxed --frames 2 --resume
err_has "initial state .* differs .*did a mesh file it reads change"

# --- a rerun without --resume starts over: old frames and state removed
run 0 run scene.yaml -q -o changed --set "$SMALL" --frames 1
[ ! -e changed/frames/frame_0002.ply ] || fail "a new run kept an old frame"

echo "cli_resume: all checks passed"
