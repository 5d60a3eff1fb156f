#!/bin/sh
# cli_sweep.sh CLOTHSIM_EXE SOURCE_DIR: `clothsim sweep` runs a scene per
# setting plus a reference, and writes sweep.csv, sweep.md and sweep.png:
# the reference against itself has zero error, a looser CG tolerance a
# larger one, a varied resolution the measures needing no correspondence;
# a bad --vary is refused (exit 2) before any run folder is written.
# --analytic incline measures the sliding tetrahedron of Fig. 8 against the
# analytic rigid body (common/incline.h): the improved friction follows it,
# the previous method (projection) does not; trajectory.png and
# cumulative_time.png are drawn.
set -eu

NAME=cli_sweep
. "$2/tests/harness.sh"
# One OpenMP thread per run: this tests what sweep measures, not threads,
# and under ctest -j a team per run spins against the other tests, which
# makes this test several times slower on a busy machine.
export OMP_NUM_THREADS=1

cat >tiny.yaml <<'YAML'
# A 6x6 sheet falling onto a ball: a few frames, so the CG tolerance shows.
cloths: [{grid: {size: [1, 1], resolution: [6, 6], center: [0, 0.3, 0]}}]
bodies: [{shape: sphere, position: [0, 0, 0], radius: 0.25}, {shape: plane}]
time: {frames: 4}
YAML

# --- help
run 0 help sweep
for opt in --vary --reference --set --output; do
    grep -q -- "$opt" out.txt || fail "'help sweep' does not explain $opt"
done
grep -q 'all threads' out.txt || fail "'help sweep' does not say the runs use all threads"

# --- bad settings: refused before anything runs
run 2 sweep tiny.yaml --vary time.no_such_key=1,2 -o bad
err_has 'no_such_key'
run 2 sweep tiny.yaml --vary time.cg_tolerance=1e-3,abc -o bad
err_has 'cg_tolerance'
run 2 sweep tiny.yaml --vary time.cg_tolerance -o bad
err_has 'KEY=V1,V2'
run 2 sweep tiny.yaml --vary time.cg_tolerance=1e-3,,1e-4 -o bad
run 2 sweep tiny.yaml --vary gravity=[0,-9,0],[0,-10,0] -o bad
err_has 'give --reference'
run 2 sweep tiny.yaml --vary time.cg_tolerance=1e-3 --reference time.dt=1e-3 -o bad
[ ! -e bad ] || fail "a refused sweep wrote $(ls -R bad)"
run 1 sweep tiny.yaml -o bad
run 1 sweep tiny.yaml --vary time.cg_tolerance=1e-3
[ ! -e bad ] || fail "a refused sweep wrote bad/"
# --analytic's value is the command's own option, not a scene setting: a
# bad one is a bad command line (exit 1), as an unknown option is
run 1 sweep tiny.yaml --vary time.cg_tolerance=1e-3,1e-4 --analytic sphere -o bad
err_has 'incline'
run 1 sweep tiny.yaml --vary time.cg_tolerance=1e-3,1e-4 --repeat 0 -o bad
err_has 'repeat'
# a scene without one plane has no incline to follow: the scene is what is
# wrong (exit 2), before anything runs
sed 's/, {shape: plane}//' tiny.yaml >noplane.yaml
run 2 sweep noplane.yaml --vary time.cg_tolerance=1e-3,1e-4 --analytic incline -o bad
err_has 'one plane'
[ ! -e bad ] || fail "a refused sweep wrote bad/"

# --- a CG tolerance sweep: the tightest (1e-4) is the reference
run 0 sweep tiny.yaml --vary time.cg_tolerance=1e-1,1e-2,1e-4 -o tol
[ "$(grep -c '^run [0-9] of 3 (time.cg_tolerance=.*ETA' err.txt)" -eq 3 ] ||
    fail "expected 3 progress lines"
head -n 1 err.txt | grep -q 'cg_tolerance=1e-4, reference' || fail "the reference runs first"
for f in sweep.csv sweep.md sweep.png run_001_time.cg_tolerance=1e-1/summary.json \
         run_003_time.cg_tolerance=1e-4/errors.csv; do
    [ -s "tol/$f" ] || fail "no tol/$f"
done
head -c 8 tol/sweep.png | grep -q 'PNG' || fail "sweep.png is not a PNG"
head -c 8 tol/cumulative_time.png | grep -q 'PNG' || fail "cumulative_time.png is not a PNG"
[ ! -e tol/trajectory.png ] || fail "trajectory.png without --analytic"
python3 - tol <<'PY' || fail "sweep.csv check"
import csv, sys
d = sys.argv[1]
rows = list(csv.DictReader(open(d + "/sweep.csv")))
assert [r["time.cg_tolerance"] for r in rows] == ["1e-1", "1e-2", "1e-4"], rows
assert [r["reference"] for r in rows] == ["no", "no", "yes"], rows
for r in rows:
    assert r["status"] == "ok", r
    assert float(r["wall_s"]) > 0 and int(r["steps"]) > 0 and int(r["cg_iterations"]) > 0, r
ref = rows[2]
for k in ("vertex_rms_m", "vertex_max_m", "com_m", "bbox_m", "hausdorff_m", "error_m"):
    assert float(ref[k]) == 0, ("reference against itself", k, ref[k])
loose, mid = float(rows[0]["error_m"]), float(rows[1]["error_m"])
assert loose > mid and loose > 0, ("1e-1 should err more than 1e-2", loose, mid)
assert float(rows[0]["vertex_max_m"]) >= float(rows[0]["vertex_rms_m"]) > 0, rows[0]
md = open(d + "/sweep.md").read().splitlines()
assert len(md) == 2 + len(rows) and md[1].startswith("| --- |"), md
per_frame = list(csv.DictReader(open(d + "/run_001_time.cg_tolerance=1e-1/errors.csv")))
worst = max(float(f["vertex_max_m"]) for f in per_frame)  # sweep.csv has 6 digits
assert len(per_frame) == 5 and abs(worst - loose) <= 1e-5 * loose, (worst, loose)
PY

# --- a varied resolution: no vertex correspondence, Hausdorff instead;
# --reference picks a value outside the list (a run of its own)
run 0 sweep tiny.yaml --set time.frames=4 --vary 'cloths.0.grid.resolution=[4,4],[5,5]' \
    --reference 'cloths.0.grid.resolution=[6,6]' -o res --quiet
if grep -q '^run ' err.txt; then fail "--quiet still printed progress"; fi
[ -s res/reference_cloths.0.grid.resolution=6x6/summary.json ] || fail "no reference run"
python3 - res <<'PY' || fail "resolution sweep check"
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1] + "/sweep.csv")))
assert [r["run"] for r in rows] == ["1", "2", "reference"], rows
assert rows[0]["folder"] == "run_001_cloths.0.grid.resolution=4x4", rows[0]
for r in rows[:2]:
    assert r["vertex_rms_m"] == "" and r["vertex_max_m"] == "", r
    assert float(r["hausdorff_m"]) > 0 and float(r["com_m"]) >= 0, r
    assert r["error_m"] == r["hausdorff_m"], r
assert float(rows[2]["hausdorff_m"]) == 0 and float(rows[2]["vertex_max_m"]) == 0, rows[2]
PY

# --- --analytic incline: Fig. 8's decelerating tetrahedron (v0 = 1 m/s down
# a 36 degree slope, mu = 0.9: it stops after 0.73 s), its first 0.12 s.
# effects.friction has no tightest value: with --analytic the first is the
# reference, no --reference needed.
run 0 sweep "$2/scenes/validation/tetrahedron_decelerating.yaml" --set time.frames=12 \
    --vary effects.friction=improved,projection --analytic incline -o incline --quiet
grep -q 'trajectory.png' out.txt || fail "the summary line does not list trajectory.png"
for f in sweep.png trajectory.png cumulative_time.png; do
    [ -s "incline/$f" ] || fail "no incline/$f"
    head -c 8 "incline/$f" | grep -q 'PNG' || fail "incline/$f is not a PNG"
done
python3 - incline <<'PY' || fail "analytic sweep check"
import csv, sys
d = sys.argv[1]
rows = {r["effects.friction"]: r for r in csv.DictReader(open(d + "/sweep.csv"))}
improved, projection = float(rows["improved"]["analytic_m"]), float(rows["projection"]["analytic_m"])
assert rows["improved"]["reference"] == "yes", rows
# test_incline's tolerance: 1e-3 of the distance travelled (here 0.11 m),
# at least 1e-4 m
assert improved < 1e-3, ("improved friction strays from the analytic body", improved)
assert projection > 50 * improved and projection > 0.01, ("projection should be far off",
                                                         projection, improved)
for name, r in rows.items():
    assert r["error_m"] == r["analytic_m"], ("error_m is analytic_m", r)
per_frame = list(csv.DictReader(open(d + "/" + rows["improved"]["folder"] + "/errors.csv")))
assert len(per_frame) == 13, len(per_frame)
last = per_frame[-1]
exact = 1.0 * 0.12 + 0.5 * 9.8 * (0.5877852522924731 - 0.9 * 0.8090169943749475) * 0.12 ** 2
assert abs(float(last["travel_analytic_m"]) - exact) < 1e-9, (last, exact)
assert abs(float(last["travel_m"]) - exact) < 1e-3, (last, exact)
assert float(per_frame[0]["travel_m"]) == 0 and float(per_frame[0]["analytic_m"]) == 0
worst = max(float(f["analytic_m"]) for f in per_frame)
assert abs(worst - improved) <= 1e-5 * improved + 1e-12, (worst, improved)
PY
exit 0
