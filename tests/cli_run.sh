#!/bin/sh
# cli_run.sh CLOTHSIM_EXE SOURCE_DIR: `clothsim run` on a tiny scene writes
# every frame, a summary and a stage table; --plan, --set, --frames and
# --format do what they say.
set -eu

NAME=cli_run
. "$2/tests/harness.sh"

# count_frames DIR EXT: number of frame files in DIR/frames.
count_frames() {
    find "$1/frames" -maxdepth 1 -name "frame_*.$2" | wc -l | tr -d ' '
}

# check_summary DIR FRAMES STATUS: summary.json parses and describes FRAMES
# simulated frames (FRAMES + 1 files) with status STATUS.
check_summary() {
    python3 - "$1/summary.json" "$2" "$3" <<'EOF' || fail "summary check of $1/summary.json"
import json, sys
path, frames, status = sys.argv[1], int(sys.argv[2]), sys.argv[3]
s = json.load(open(path))
def need(cond, what):
    if not cond:
        sys.exit("summary.json: %s\n%s" % (what, json.dumps(s, indent=1)[:3000]))
for key in ("scene", "scene_file", "clothsim_version", "status", "frames_written", "fps",
            "dt", "steps_per_frame", "particles", "triangles", "plan", "stages",
            "total_seconds", "frames"):
    need(key in s, "no key %r" % key)
need(s["status"] == status, "status %r, expected %r" % (s["status"], status))
need(len(s["frames"]) == frames, "%d frame entries, expected %d" % (len(s["frames"]), frames))
need(s["frames_written"] == frames + 1, "frames_written %r" % s["frames_written"])
need(s["particles"] == 25 and s["triangles"] == 32, "a 4x4 grid has 25 particles, 32 triangles")
need(s["dt"] > 0 and s["fps"] > 0 and s["steps_per_frame"] >= 1, "dt, fps, steps_per_frame")
need(isinstance(s["plan"], list) and len(s["plan"]) > 0, "empty plan")
need([st["name"] for st in s["stages"]] == s["plan"], "stages do not follow the plan")
for st in s["stages"]:
    for key in ("name", "seconds", "share", "calls", "bytes"):
        need(key in st, "stage without %r" % key)
    need(st["seconds"] >= 0 and 0 <= st["share"] <= 1, "stage %r timing" % st["name"])
if frames > 0:
    need(any(st["calls"] > 0 for st in s["stages"]), "no stage was called")
for k, f in enumerate(s["frames"], start=1):
    need(f["frame"] == k, "frame entry %d is numbered %r" % (k, f["frame"]))
    for key in ("time", "steps", "dt", "cg_iterations", "body_contacts", "max_speed", "seconds"):
        need(key in f, "frame %d without %r" % (k, key))
    need(f["steps"] >= 1, "frame %d took no steps" % k)
    need(abs(f["time"] - k / s["fps"]) < 1e-6, "frame %d at t=%r" % (k, f["time"]))
EOF
}

# check_files DIR EXT N: DIR/frames holds exactly frame_0000 .. frame_N of
# that format, each starting like one, and nothing half-written.
check_files() {
    n=$(count_frames "$1" "$2")
    [ "$n" -eq $(($3 + 1)) ] || fail "$1/frames has $n .$2 files, expected $(($3 + 1))"
    k=0
    while [ "$k" -le "$3" ]; do
        f=$(printf '%s/frames/frame_%04d.%s' "$1" "$k" "$2")
        [ -s "$f" ] || fail "missing or empty $f"
        case $2 in
        ply) head -c 3 "$f" | grep -q '^ply' || fail "$f is not PLY" ;;
        glb) head -c 4 "$f" | grep -q '^glTF' || fail "$f is not glb" ;;
        obj) grep -q '^v ' "$f" || fail "$f has no vertices" ;;
        esac
        k=$((k + 1))
    done
    if find "$1" -name '*.tmp' | grep -q .; then
        fail "temporary files left in $1"
    fi
}

cat >tiny.yaml <<'EOF'
# A 4x4 grid of cloth half a metre above the floor.
cloths: [{grid: {size: [1, 1], resolution: [4, 4], center: [0, 0.5, 0]}}]
bodies: [{shape: plane, friction: 0.3}]
time: {frames: 3}
EOF

# --- help and version
run 0 --help
grep -q 'run' out.txt || fail "--help does not mention run"
run 0 --version
grep -q '^clothsim [0-9]' out.txt || fail "--version printed '$(cat out.txt)'"
run 0 help run
for opt in --output --set --format --frames --plan --quiet; do
    grep -q -- "$opt" out.txt || fail "'help run' does not explain $opt"
done
run 0 run --help
grep -q -- '--frames' out.txt || fail "'run --help' does not explain --frames"

# --- a plain run into the default directory out/<scene name>
run 0 run tiny.yaml
check_files out/tiny ply 3
check_summary out/tiny 3 ok
grep -q 'stage' out.txt || fail "no stage table on stdout"
grep -q 'all stages' out.txt || fail "stage table without a total"
grep -q 'per frame' out.txt || fail "no time per frame on stdout"
# stderr is not a terminal here: one plain progress line per frame.
[ "$(grep -c '^frame [0-9]*/3' err.txt)" -eq 3 ] || fail "expected 3 progress lines on stderr"
if grep -q "$(printf '\r')" err.txt; then
    fail "progress redrawn with CR although stderr is not a terminal"
fi
python3 -c '
import json, sys
s = json.load(open("out/tiny/summary.json"))
plan = s["plan"]
out = open("out.txt").read()
missing = [p for p in plan if p not in out]
sys.exit("stage table lacks %s" % missing if missing else 0)
' || fail "stage table does not list every planned stage"

# --- --quiet: no progress
run 0 run tiny.yaml --quiet -o quiet
[ ! -s err.txt ] || fail "--quiet still printed on stderr"
check_files quiet ply 3

# --- --plan prints the plan and writes nothing
run 0 run tiny.yaml --plan -o planned
[ ! -e planned ] || fail "--plan created its output directory"
grep -q '1\. ' out.txt || fail "--plan printed no numbered stages"
grep -q 'step' out.txt || fail "--plan printed no step size"
grep -q 'memory: .* for the setup .*a run needs about ' out.txt || fail "--plan printed no memory estimate"
python3 -c '
import json, sys
plan = json.load(open("out/tiny/summary.json"))["plan"]
out = open("out.txt").read()
sys.exit(0 if all(p in out for p in plan) else "plan output lacks stages")
' || fail "--plan does not name the planned stages"
! grep -q 'pruning' out.txt || fail "--plan names a pruning the scene did not ask for"
run 0 run tiny.yaml --plan --set effects.self_collision=true --set self_collision.pruning=path
grep -q 'self_collision.pruning path' out.txt || fail "--plan does not say step A prunes by path"

# --- the stages --plan numbers are the summary's stage table, in order,
# and each ran; the rows it leaves out never ran (self-collision off, on)
for self in false true; do
    run 0 run tiny.yaml --plan --set effects.self_collision=$self
    cp out.txt plan_$self.txt
    run 0 run tiny.yaml -q -o staged_$self --frames 1 --set effects.self_collision=$self
    python3 - plan_$self.txt staged_$self/summary.json <<'EOF' || fail "--plan is not what ran (self_collision $self)"
import json, re, sys
text = open(sys.argv[1]).read()
planned = re.findall(r"^ +\d+\. (\S+)", text, re.M)
left_out = re.findall(r"^ +- +(\S+) +left out", text, re.M)
s = json.load(open(sys.argv[2]))
ran = [st["name"] for st in s["stages"]]
if planned != s["plan"] or planned != ran:
    sys.exit("--plan %s, summary plan %s, stages %s" % (planned, s["plan"], ran))
idle = [st["name"] for st in s["stages"] if st["calls"] < 1]
if idle:
    sys.exit("planned stages that never ran: %s" % idle)
if set(left_out) & set(ran) or len(planned) + len(left_out) != 13:
    sys.exit("left out %s against ran %s" % (left_out, ran))
EOF
done
grep -q 'collisions  *C:' plan_true.txt || fail "--plan with self-collision lacks step C"
grep -q 'collisions  *left out: needs effects.self_collision' plan_false.txt ||
    fail "--plan does not say what step C needs"

# --- overrides: --set time.frames=1, --frames 2; a rerun replaces old frames
run 0 run tiny.yaml -q -o one --set time.frames=1
check_files one ply 1
check_summary one 1 ok
run 0 run tiny.yaml -q -o one --frames 2
check_files one ply 2
check_summary one 2 ok
run 0 run tiny.yaml -q -o one --frames 0
check_files one ply 0
check_summary one 0 ok

# --- every output format
for fmt in ply obj glb; do
    run 0 run tiny.yaml -q -o "fmt_$fmt" --format "$fmt" --frames 1
    check_files "fmt_$fmt" "$fmt" 1
    check_summary "fmt_$fmt" 1 ok
    python3 -c 'import json,sys; sys.exit(json.load(open(sys.argv[1]))["format"] != sys.argv[2])' \
        "fmt_$fmt/summary.json" "$fmt" || fail "summary format is not $fmt"
done
# output.format of the scene applies, --format wins over it
run 0 run tiny.yaml -q -o fmt_set --set output.format=obj --frames 1
check_files fmt_set obj 1
run 0 run tiny.yaml -q -o fmt_both --set output.format=obj --format glb --frames 1
check_files fmt_both glb 1

# --- a run that blows up: status 3, the frames before kept, summary "unstable"
# (gravity near the largest double overflows the velocities within a frame)
run 3 run tiny.yaml -q -o unstable --set 'gravity=[0,-1e308,0]' --set 'bodies=[]' --frames 5
grep -q 'unstable in frame [0-9]' err.txt || fail "the instability message names no frame"
python3 - unstable <<'EOF' || fail "unstable run: files and summary disagree"
import json, os, sys
d = sys.argv[1]
s = json.load(open(os.path.join(d, "summary.json")))
files = sorted(os.listdir(os.path.join(d, "frames")))
assert s["status"] == "unstable", s["status"]
assert s["frames_written"] == len(files) >= 1, (s["frames_written"], files)
assert len(s["frames"]) == len(files) - 1
assert s["failed_frame"] == len(files), s["failed_frame"]
EOF

# --- SIGTERM: status 130, every frame written so far kept, summary "interrupted"
status=0
"$EXE" run tiny.yaml -q -o stopped --frames 100000 >out.txt 2>err.txt &
pid=$!
tries=0
while [ ! -e stopped/frames/frame_0002.ply ] && [ "$tries" -lt 600 ]; do
    sleep 0.1
    tries=$((tries + 1))
done
kill -TERM "$pid" 2>/dev/null || true
wait "$pid" || status=$?
[ "$status" -eq 130 ] || fail "SIGTERM: exited $status, expected 130"
grep -q 'interrupted' err.txt || fail "SIGTERM: no message"
python3 - stopped <<'EOF' || fail "interrupted run: files and summary disagree"
import json, os, sys
d = sys.argv[1]
s = json.load(open(os.path.join(d, "summary.json")))
files = sorted(os.listdir(os.path.join(d, "frames")))
assert s["status"] == "interrupted", s["status"]
assert len(files) >= 3 and s["frames_written"] == len(files), (s["frames_written"], len(files))
assert len(s["frames"]) == len(files) - 1
assert files[-1] == "frame_%04d.ply" % (len(files) - 1), files[-1]
EOF

echo "cli_run: all checks passed"
