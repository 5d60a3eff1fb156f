#!/bin/sh
# cli_stability.sh CLOTHSIM_EXE SOURCE_DIR: steps and sizes a scene cannot
# take are refused at load with the reason (exit 2), a step above the
# stability limit is warned about with the limit shown, and a run that blows
# up is caught early, named with its frame and stage, and stops with exit 3
# and the frames before it kept.
set -eu

NAME=cli_stability
. "$2/tests/harness.sh"
DRAPE="$2/scenes/drape.yaml"
SMALL="cloths.0.grid.resolution=[16,16]"

# a step too small to count used to overflow into one step per frame
run 2 run "$DRAPE" --set time.dt=1e-12 --plan
err_has 'time.dt is too small: 1e-12 s makes a frame of 0.0417 s 4.17e\+10 steps'
# a stiffness that makes the stability limit 0 s
run 2 run "$DRAPE" --set cloths.0.material.edge_stiffness=1e308 --plan
err_has 'stability limit of the cloths.* springs is 0 s'
# frames: one limit for the scene key and the option
run 2 run "$DRAPE" --set time.frames=1000000000 --plan
err_has 'time.frames: must be at most 100000000'
run 1 run "$DRAPE" --frames 1000000000 --plan
err_has 'from 0 to 100000000'

# a grid that cannot fit is refused before anything is allocated: in bounded
# time and memory (this once took 13.8 GB); ulimit -v would catch a regression
# that allocates, but not under AddressSanitizer, which reserves terabytes
run 2 run "$DRAPE" --set 'cloths.0.grid.resolution=[20000,17000]' --plan
err_has 'cloths\[0\].grid.resolution: 20000 x 17000 quads \(3.4e\+08 particles\) to simulate: would need about .* of memory, but .* is available'
[ ! -s out.txt ] || fail "a refused scene printed a plan"

# --plan builds only what the step size needs (mesh, masses, springs for
# Lanczos: about 0.5 kB a particle), not the step's arrays, the solver or
# self-collision (6 kB a particle estimated for a run): a 400 x 400 sheet
python3 - "$EXE" "$DRAPE" <<'EOF' || fail "--plan allocated what a run needs"
import resource, subprocess, sys
exe, scene = sys.argv[1:3]
subprocess.run([exe, "run", scene, "--plan", "--set", "cloths.0.grid.resolution=[400,400]",
                "--set", "effects.self_collision=true"], check=True, stdout=subprocess.DEVNULL)
peak = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss * 1024
run_estimate = 6000 * 401 * 401
assert peak < 0.4 * run_estimate, (peak, run_estimate)
EOF

# With Table 1's overdamping this coarse sheet's damped limit is longer than
# a frame; without damping the limit is the undamped 2 / omega_max
UNDAMPED="--set cloths.0.material.edge_overdamping=0 --set cloths.0.material.bend_overdamping=0"

# a fixed step above the limit is allowed (the limit is sufficient, not
# necessary) but warned
run 0 run "$DRAPE" --set "$SMALL" $UNDAMPED --set time.dt=0.003 --plan
err_has 'warning: .*time.dt 0.003 s is 1.19 times the stability limit 0.00251 s'

# one step per frame, 17 times the limit: blows up when the sheet meets the
# ball; caught at tens of m/s (the issue saw 1.4e6 m/s reported as "ok")
run 3 run "$DRAPE" --set "$SMALL" $UNDAMPED --set time.dt=0.0417 -o blown -q
err_has 'unstable in frame [0-9]+ \(t=[0-9.]+ s\): speed [0-9.]+ m/s after stage (velocity_half|velocity_full|body_collision|body_friction), beyond the [0-9.]+ m/s'
python3 - blown <<'EOF' || fail "unstable run: frames or summary wrong"
import json, os, re, sys
d = sys.argv[1]
s = json.load(open(os.path.join(d, "summary.json")))
files = sorted(os.listdir(os.path.join(d, "frames")))
assert s["status"] == "unstable", s["status"]
assert s["failed_frame"] == len(files) >= 2, (s["failed_frame"], files)
speed, limit = map(float, re.search(r"speed ([0-9.e+]+) m/s .* the ([0-9.e+]+) m/s", s["error"]).groups())
assert limit < speed < 1000, (speed, limit)
EOF

# the same scene at its automatic step: no false alarm
run 0 run "$DRAPE" --set "$SMALL" -o calm -q --frames 20
echo "$NAME: ok"
