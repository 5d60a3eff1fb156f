#!/bin/sh
# cli_output.sh CLOTHSIM_EXE SOURCE_DIR: the output folder.
# - Every write is checked: a file-size limit (ulimit -f: EFBIG) on a frame
#   (written through assimp), on state.h5 (HDF5) and on frames.jsonl mid-run,
#   and /dev/full (ENOSPC) on summary.json and state.h5, each exit 4 naming
#   the file, with no truncated file under a final name and the frames
#   before kept (the same bytes as a run that was not starved), and
#   --resume continuing from what was kept.
# - One run per folder: a second run, on one rank or two, is refused (exit 4)
#   naming the holder; kill -9 leaves no lock behind.
# - summary.json keeps a constant size while running (records go to
#   frames.jsonl) and carries each frame's state hash, the same for the same
#   run.
set -eu

NAME=cli_output
. "$2/tests/harness.sh"
MPIEXEC=${MPIEXEC:-mpirun}

# one quad at 240 frames a second: many frames fast
cat >micro.yaml <<'EOF'
time: {fps: 240}
cloths: [{grid: {size: [1, 1], resolution: [1, 1], center: [0, 0.5, 0]}}]
bodies: [{shape: plane, friction: 0.3}]
EOF

size() { wc -c <"$1" | tr -d ' '; }

# limited BYTES EXPECTED_STATUS ARGS...: clothsim with files limited to
# BYTES (RLIMIT_FSIZE, as ulimit -f sets it), SIGXFSZ at its default: clothsim
# ignores it itself, so the write fails with EFBIG instead of killing it.
limited() {
    bytes=$1
    want=$2
    shift 2
    status=0
    python3 -c '
import os, resource, signal, sys
n = int(sys.argv[1])
resource.setrlimit(resource.RLIMIT_FSIZE, (n, n))
signal.signal(signal.SIGXFSZ, signal.SIG_DFL)
os.execv(sys.argv[2], sys.argv[2:])
' "$bytes" "$EXE" "$@" >out.txt 2>err.txt || status=$?
    [ "$status" -eq "$want" ] || fail "clothsim $* limited to $bytes B exited $status, expected $want"
}

# no_tmp DIR: nothing half-written left.
no_tmp() {
    if find "$1" -name '*.tmp' | grep -q .; then
        fail "temporary files left in $1: $(find "$1" -name '*.tmp')"
    fi
}

# same_kept DIR REF: every frame file of DIR is the same bytes as REF's.
same_kept() {
    for f in "$1"/frames/frame_*; do
        cmp -s "$f" "$2/frames/$(basename "$f")" || fail "$f differs from $2's"
    done
}

# summary_says DIR KEY VALUE: summary.json's KEY is VALUE (as JSON).
summary_says() {
    python3 -c '
import json, sys
s = json.load(open(sys.argv[1] + "/summary.json"))
v = s.get(sys.argv[2])
sys.exit(0 if v == json.loads(sys.argv[3]) else "%s is %r" % (sys.argv[2], v))
' "$1" "$2" "$3" || fail "$1/summary.json: $2 should be $3"
}

# --- hashes: the same run gives the same hashes; records = summary frames
run 0 run micro.yaml -q -o ref --frames 3
run 0 run micro.yaml -q -o ref2 --frames 3
run 0 run micro.yaml -q -o other --frames 3 --set 'gravity=[0,-9.7,0]'
python3 - <<'EOF' || fail "state hashes"
import json, re
a, b, c = (json.load(open(d + "/summary.json")) for d in ("ref", "ref2", "other"))
hashes = lambda s: [s["initial_state_hash"]] + [f["state_hash"] for f in s["frames"]]
assert all(re.fullmatch("[0-9a-f]{32}", h) for h in hashes(a)), hashes(a)
assert hashes(a) == hashes(b), "the same run hashes differently"
assert len(set(hashes(a))) == 4, "frames hash alike"
assert hashes(a)[0] == hashes(c)[0] and hashes(a)[1:] != hashes(c)[1:], "hash ignores gravity"
assert "XXH3-128" in a["state_hash_algorithm"]
recs = [json.loads(l) for l in open("ref/frames.jsonl")]
assert recs == a["frames"], "summary frames are not the records"
EOF

# --- a limit below a frame's size: the frame (through assimp) fails
F=$(size ref/frames/frame_0000.ply)
S=$(size ref/state.h5)
[ "$F" -lt "$S" ] || fail "expected a frame ($F B) smaller than state.h5 ($S B)"
limited $((F / 2)) 4 run micro.yaml -q -o fsz1 --frames 2
err_has "cannot write fsz1/frames/frame_0000.ply: File too large"
err_has "a frame file could not be written; no frame is kept"
[ ! -e fsz1/frames/frame_0000.ply ] || fail "a truncated frame 0 under its final name"
no_tmp fsz1
# nor does summary.json fit: none rather than a truncated one
err_has "cannot write fsz1/summary.json: File too large"
[ ! -e fsz1/summary.json ] || fail "a summary.json under a limit it exceeds"

# --- a limit between the frame and the state: HDF5's write fails
limited $(((F + S) / 2)) 4 run micro.yaml -q -o fsz2 --frames 2
err_has "cannot write fsz2/state.h5: File too large"
err_has "frame 0 is kept in fsz2/frames"
same_kept fsz2 ref
[ ! -e fsz2/state.h5 ] || fail "a state.h5 from a failed write"
no_tmp fsz2
summary_says fsz2 error '"the state to resume from could not be written"'

# --- mid-run: frames.jsonl grows past the limit; frames before it kept,
# records cut back to whole ones, the state intact: --resume finishes the
# run with the frames of one never starved
run 0 run micro.yaml -q -o tref --frames 120
L=$(($(size tref/state.h5) + 4096))
[ "$(size tref/frames.jsonl)" -gt "$L" ] || fail "frames.jsonl stays under the limit"
limited "$L" 4 run micro.yaml -q -o fsz3 --frames 120
err_has "cannot write fsz3/frames.jsonl: File too large"
no_tmp fsz3
same_kept fsz3 tref
python3 - <<'EOF' || fail "records after the failed write"
import json, os
recs = [json.loads(l) for l in open("fsz3/frames.jsonl")]  # each line whole
k = len(recs)
assert k >= 10 and [r["frame"] for r in recs] == list(range(1, k + 1)), k
frames = sorted(os.listdir("fsz3/frames"))
# the frame whose record failed was written first and is kept
assert frames == ["frame_%04d.ply" % i for i in range(k + 2)], (k, frames[-3:])
# the final summary did not fit either: the last one written while running
# stays, describing frames already written (it is rewritten once a second)
s = json.load(open("fsz3/summary.json"))
assert s["status"] == "running" and 1 <= s["frames_written"] <= k + 1, s["frames_written"]
EOF
run 0 run micro.yaml -q -o fsz3 --frames 120 --resume
same_kept fsz3 tref
python3 -c '
import json
a, b = (json.load(open(d + "/summary.json")) for d in ("fsz3", "tref"))
assert [f["state_hash"] for f in a["frames"]] == [f["state_hash"] for f in b["frames"]]
' || fail "the resumed run's hashes differ"

# --- /dev/full: ENOSPC on summary.json, and on state.h5 of a resumed run
mkdir -p full
ln -s /dev/full full/summary.json.tmp
run 4 run micro.yaml -q -o full --frames 2
err_has "cannot write full/summary.json: No space left on device"
[ -f full/frames/frame_0000.ply ] || fail "frame 0 was not kept"
[ ! -e full/summary.json ] && [ ! -L full/summary.json.tmp ] || fail "summary.json after ENOSPC"
run 0 run micro.yaml -q -o full --frames 2
ln -s /dev/full full/state.h5.tmp
run 4 run micro.yaml -q -o full --frames 4 --resume
err_has "cannot write full/state.h5: No space left on device"
err_has "frames 0 to 3 are kept"
same_kept full tref
run 0 run micro.yaml -q -o full --frames 4 --resume
same_kept full tref
[ -f full/frames/frame_0004.ply ] || fail "no frame 4 after resuming"

# --- the lock, and summary.json's constant size while running
"$EXE" run micro.yaml -q -o busy --frames 100000 >busy.out 2>&1 &
pid=$!
trap 'kill -KILL $pid 2>/dev/null || true; rm -rf "$TMP"' EXIT INT TERM
records() { # whole records in busy/frames.jsonl
    if [ -f busy/frames.jsonl ]; then grep -c . busy/frames.jsonl || true; else echo 0; fi
}
wait_records() { # wait_records N: until frames.jsonl has N records
    tries=0
    while [ "$(records)" -lt "$1" ]; do
        [ "$tries" -lt 1200 ] || fail "the busy run wrote no $1 records: $(cat busy.out)"
        sleep 0.05
        tries=$((tries + 1))
    done
}
written() { # frames_written in busy/summary.json
    python3 -c 'import json; print(json.load(open("busy/summary.json"))["frames_written"])'
}
wait_records 3
run 4 run micro.yaml -q -o busy --frames 2
err_has "busy is in use by another clothsim run \(pid $pid on host [^ ]+ since"
run 4 run micro.yaml -q -o busy --frames 2 --resume
err_has "in use by another clothsim run \(pid $pid"
mpi_status=0 # (no leak checks under mpirun: see cli_resume.sh)
ASAN_OPTIONS=detect_leaks=0 "$MPIEXEC" --oversubscribe -np 2 "$EXE" run micro.yaml -q -o busy --frames 2 >out.txt 2>err.txt ||
    mpi_status=$?
[ "$mpi_status" -eq 4 ] || fail "two ranks into a busy folder exited $mpi_status, expected 4"
[ "$(grep -c 'in use by another clothsim run' err.txt)" -eq 1 ] || fail "not one message from two ranks"
[ -f busy/frames/frame_0001.ply ] || fail "a refused run removed the busy run's frames"
s1=$(size busy/summary.json)
w1=$(written)
tries=0
while [ "$(written)" -lt $((w1 + 40)) ]; do # rewritten once a second
    [ "$tries" -lt 1200 ] || fail "busy/summary.json is not rewritten"
    sleep 0.05
    tries=$((tries + 1))
done
s2=$(size busy/summary.json)
python3 -c '
import json; assert "frames" not in json.load(open("busy/summary.json"))' ||
    fail "a running summary.json carries the records"
# the same size but for digits: 40 frames' records would be 10 kB
[ "$s2" -le $((s1 + 64)) ] || fail "summary.json grew from $s1 to $s2 bytes over 40 frames"
kill -KILL "$pid"
wait "$pid" 2>/dev/null || true
# the lock died with its holder
run 0 run micro.yaml -q -o busy --frames 2
[ ! -e busy/frames/frame_0003.ply ] || fail "old frames kept by a new run"
summary_says busy status '"ok"'

echo "cli_output: all checks passed"
