#!/bin/sh
# cli_threads.sh CLOTHSIM_EXE SOURCE_DIR: OpenMP threads inside a rank.
# The same scene gives the same bits at 1, 2 and 3 threads:
# springs are gathered per particle in a fixed order, inner products are
# summed in fixed blocks, collision candidates are joined in the traversal's
# order. Hybrid runs (2 ranks of 1 thread against 1 rank of 2) agree as rank
# counts do (round-off of reductions summed per rank).
set -eu

NAME=cli_threads
. "$2/tests/harness.sh"
SCENES="$2/scenes"
MPIEXEC=${MPIEXEC:-mpirun}

same_frames() { # DIR_A DIR_B: every frame file byte for byte, same counters
    for f in "$1"/frames/*; do
        cmp -s "$f" "$2/frames/$(basename "$f")" || fail "$(basename "$f") differs between $1 and $2"
    done
    python3 - "$1/summary.json" "$2/summary.json" <<'PY' || fail "per-frame counters differ: $1 $2"
import json, sys
a, b = (json.load(open(p)) for p in sys.argv[1:3])
keys = ("steps", "cg_iterations", "body_contacts", "repulsion_pairs", "repulsions",
        "collisions", "collision_passes", "impact_zones", "intersections")
for fa, fb in zip(a["frames"], b["frames"]):
    for k in keys:
        assert fa.get(k) == fb.get(k), (k, fa.get(k), fb.get(k))
assert len(a["frames"]) == len(b["frames"])
PY
}

# self-collision with step C at work: collisions, passes and zones
for t in 1 2 3; do
    run 0 run "$SCENES/stack.yaml" -o stack$t --frames 5 --threads $t \
        --set self_collision.zone_iterations=1 -q
done
python3 - stack1/summary.json <<'PY' || fail "the stack test has no collisions to compare"
import json, sys
s = json.load(open(sys.argv[1]))
assert s["threads"] == 1, s["threads"]
assert sum(f.get("collisions", 0) for f in s["frames"]) > 0
assert all(f.get("intersections") == 0 for f in s["frames"][1:])
PY
python3 -c 'import json,sys; assert json.load(open(sys.argv[1]))["threads"] == 3' \
    stack3/summary.json || fail "summary.json does not record 3 threads"
same_frames stack1 stack2
same_frames stack1 stack3

# a drape with body contact (the sheet lands in frame 6), CG at work and
# 625 particles: ten blocks of rows to share; the fixed undamped step
# (auto takes the damped one for this cloth, compared below)
for t in 1 2; do
    run 0 run "$SCENES/drape.yaml" -o drape$t --frames 9 --threads $t \
        --set 'cloths.0.grid.resolution=[24,24]' --set time.step_limit=undamped -q
done
same_frames drape1 drape2
python3 - drape1/summary.json <<'PY' || fail "the drape never touched the ball"
import json, sys
s = json.load(open(sys.argv[1]))
assert sum(f["body_contacts"] for f in s["frames"]) > 0 and sum(f["cg_iterations"] for f in s["frames"]) > 0
PY

# the damped step limit: the step is chosen before every outer step from
# maxima over particles, so threads see the same steps and the same bits;
# the steps change with the tension (fewer in free fall than in contact)
for t in 1 2; do
    run 0 run "$SCENES/drape.yaml" -o damped$t --frames 9 --threads $t \
        --set 'cloths.0.grid.resolution=[24,24]' --set time.step_limit=damped -q
done
same_frames damped1 damped2
python3 - damped1/summary.json drape1/summary.json <<'PY' || fail "the damped step did not adapt"
import json, sys
d, u = (json.load(open(p))["frames"] for p in sys.argv[1:3])
steps = [f["steps"] for f in d]
assert min(steps) < max(steps), steps  # free fall against contact
assert sum(steps) < sum(f["steps"] for f in u), (steps, [f["steps"] for f in u])
assert all(f.get("intersections", 0) == 0 for f in d)
PY

# a mesh body (an OpenVDB level set queried by both threads at once)
for t in 1 2; do
    run 0 run "$SCENES/bunny_drape.yaml" -o bunny$t --frames 8 --threads $t \
        --set 'cloths.0.grid.resolution=[24,24]' -q
done
same_frames bunny1 bunny2
python3 - bunny1/summary.json <<'PY' || fail "the sheet never touched the bunny"
import json, sys
assert sum(f["body_contacts"] for f in json.load(open(sys.argv[1]))["frames"]) > 0
PY

# bad values are refused like other options
run 1 run "$SCENES/drape.yaml" --threads 0 --plan
err_has "--threads"
run 1 run "$SCENES/drape.yaml" --threads two --plan
err_has "--threads"

# hybrid: two ranks of one thread against one rank of two threads
SMALL="--set cloths.0.grid.resolution=[16,16] --frames 3 -q"
# (the damped step is chosen from maxima over ranks: the same steps too)
DAMPED="--set time.step_limit=damped --set cloths.0.grid.resolution=[24,24] --frames 8 -q"
# shellcheck disable=SC2086
run 0 run "$SCENES/drape.yaml" -o damped_one2 --threads 2 $DAMPED
status=0
# shellcheck disable=SC2086
"$MPIEXEC" --oversubscribe -np 2 "$EXE" run "$SCENES/drape.yaml" -o damped_two1 --threads 1 $DAMPED \
    >out.txt 2>err.txt || status=$?
[ "$status" -eq 0 ] || fail "mpirun -np 2 clothsim run --threads 1 (damped) exited $status"
python3 - damped_one2/summary.json damped_two1/summary.json <<'PY' || fail "damped steps differ across ranks"
import json, sys
a, b = (json.load(open(p))["frames"] for p in sys.argv[1:3])
assert [f["steps"] for f in a] == [f["steps"] for f in b], (a, b)
assert len(set(f["steps"] for f in a)) > 1, [f["steps"] for f in a]
PY
# shellcheck disable=SC2086
run 0 run "$SCENES/drape.yaml" -o one2 --threads 2 $SMALL
status=0
# shellcheck disable=SC2086
"$MPIEXEC" --oversubscribe -np 2 "$EXE" run "$SCENES/drape.yaml" -o two1 --threads 1 $SMALL \
    >out.txt 2>err.txt || status=$?
[ "$status" -eq 0 ] || fail "mpirun -np 2 clothsim run --threads 1 exited $status"
python3 - one2 two1 <<'PY' || fail "two ranks of one thread do not match one rank of two"
import json, os, struct, sys
one, two = sys.argv[1], sys.argv[2]
a, b = json.load(open(one + "/summary.json")), json.load(open(two + "/summary.json"))
assert (a["ranks"], a["threads"], b["ranks"], b["threads"]) == (1, 2, 2, 1)
for fa, fb in zip(a["frames"], b["frames"]):
    assert fa["cg_iterations"] == fb["cg_iterations"], (fa, fb)
def vertices(path):
    data = open(path, "rb").read()
    head, body = data.split(b"end_header\n", 1)
    lines = head.decode().splitlines()
    nv = int([l for l in lines if l.startswith("element vertex")][0].split()[2])
    at = lines.index([l for l in lines if l.startswith("element vertex")][0])
    width = 0  # float properties of a vertex (x y z first, then normals)
    for l in lines[at + 1:]:
        if not l.startswith("property float"):
            break
        width += 1
    flat = struct.unpack_from("<%df" % (width * nv), body)
    return [flat[i * width + k] for i in range(nv) for k in range(3)]
for name in sorted(os.listdir(one + "/frames")):
    va, vb = vertices(one + "/frames/" + name), vertices(two + "/frames/" + name)
    worst = max(abs(p - q) for p, q in zip(va, vb))
    assert worst <= 1e-6, (name, worst)
PY
echo "$NAME: ok"
