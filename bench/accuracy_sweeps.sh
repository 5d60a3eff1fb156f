#!/bin/sh
# bench/accuracy_sweeps.sh [BUILD_DIR] [NAME...]: the sweeps of
# docs/accuracy.md, "What accuracy costs in time": each knob that trades accuracy for time,
# swept with `clothsim sweep` on a scene at its committed (test) size,
# shortened with --set time.frames=N. NAME picks sweeps (default: all):
#
#   incline          bench/accuracy_time.sh: dt_safety x cg_tolerance x
#                    friction on the tetrahedron incline, --analytic incline
#   friction_acc     effects.friction=improved,projection on
#   friction_dec     tetrahedron_{accelerating,decelerating}: Figs. 7, 8
#   dt_safety        drape: time.dt_safety x time.step_limit
#   cg_tolerance     drape: time.cg_tolerance
#   resolution       drape: cloths.0.grid.resolution (and its cost exponent)
#   collision_steps  stack: time.collision_steps (k_i)
#   repulsion        stack: self_collision.thickness x self_collision.stiffness
#   zone_iterations  stack: self_collision.zone_iterations
#   scheme           stack: self_collision.scheme=fixed,rewind: Fig. 14
#   twist            the twisting cloth (scenes/figures/twist.yaml, Fig. 3):
#                    time.collision_steps under high tension
#
# Each sweep runs into out/accuracy/NAME/ with --repeat $REPEAT (default 3:
# every run three times, its wall_s the median), and its tables and pictures
# are copied to gallery/accuracy/: NAME.csv, NAME.md, NAME.png (error
# against seconds), NAME_trajectory.png (--analytic), NAME_cumulative_time.png.
# The runs take $THREADS OpenMP threads each (default 1: on a shared
# machine a spinning thread team measures the neighbours, not clothsim).
# BUILD_DIR (default build) should be a Release build.
set -eu
cd "$(dirname "$0")/.."
BUILD=${1:-build}
[ $# -gt 0 ] && shift
REPEAT=${REPEAT:-3}
export OMP_NUM_THREADS="${THREADS:-1}"
OUT=out/accuracy
GALLERY=gallery/accuracy
ALL="friction_acc friction_dec cg_tolerance collision_steps zone_iterations scheme repulsion
dt_safety resolution incline twist"
# shellcheck disable=SC2086 # $ALL is a list
[ $# -gt 0 ] || set -- $ALL

die() { echo "accuracy_sweeps.sh: $*" >&2; exit 1; }
[ -x "$BUILD/clothsim" ] ||
    die "no $BUILD/clothsim: build first (cmake -S . -B $BUILD -DCMAKE_BUILD_TYPE=Release && cmake --build $BUILD)"
case $REPEAT in '' | *[!0-9]* | 0) die "REPEAT must be a whole number >= 1, not '$REPEAT'" ;; esac
mkdir -p "$OUT" "$GALLERY"

# publish NAME DIR: DIR's tables and pictures into gallery/accuracy as NAME*.
publish() {
    cp "$2/sweep.csv" "$GALLERY/$1.csv"
    cp "$2/sweep.md" "$GALLERY/$1.md"
    cp "$2/sweep.png" "$GALLERY/$1.png"
    cp "$2/cumulative_time.png" "$GALLERY/$1_cumulative_time.png"
    [ ! -f "$2/trajectory.png" ] || cp "$2/trajectory.png" "$GALLERY/$1_trajectory.png"
}

# sweep NAME SCENE ARGS...: `clothsim sweep SCENE ARGS... --repeat REPEAT`
# into out/accuracy/NAME, then published.
sweep() {
    name=$1 scene=$2
    shift 2
    echo "accuracy_sweeps.sh: $name" >&2
    rm -rf "${OUT:?}/$name"
    "$BUILD/clothsim" sweep "$scene" "$@" --repeat "$REPEAT" -o "$OUT/$name" --quiet >/dev/null
    publish "$name" "$OUT/$name"
}

# The cost exponent p of seconds ~ particles^p: between each resolution and
# the next (start-up weighs on the coarse ones), and by least squares over
# all, of the runs' wall seconds (medians); into gallery/accuracy/resolution_cost.md.
cost_exponent() {
    python3 - "$OUT/resolution/sweep.csv" "$GALLERY/resolution_cost.md" <<'EOF'
import csv, math, re, sys
rows = list(csv.DictReader(open(sys.argv[1])))
pts = []
for r in rows:
    n = [int(v) for v in re.findall(r"\d+", r["cloths.0.grid.resolution"])]
    pts.append(((n[0] + 1) * (n[1] + 1), float(r["wall_s"]), r))
pts.sort(key=lambda t: t[0])
xs = [math.log(p) for p, _, _ in pts]
ys = [math.log(s) for _, s, _ in pts]
mx, my = sum(xs) / len(xs), sum(ys) / len(ys)
p = sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sum((x - mx) ** 2 for x in xs)
with open(sys.argv[2], "w") as f:
    f.write("| resolution | particles | wall_s (median) | exponent from the previous row "
            "| steps | hausdorff_m | com_m |\n| --- | --- | --- | --- | --- | --- | --- |\n")
    for i, (n, s, r) in enumerate(pts):
        local = "%.2f" % ((ys[i] - ys[i - 1]) / (xs[i] - xs[i - 1])) if i else "–"
        f.write("| %s | %d | %.3g | %s | %s | %s | %s |\n" % (
            r["cloths.0.grid.resolution"], n, s, local, r["steps"], r["hausdorff_m"], r["com_m"]))
    f.write("\nwall seconds ~ particles^%.2f (least squares over the rows)\n" % p)
print(open(sys.argv[2]).read())
EOF
}

DRAPE="scenes/drape.yaml --set time.frames=12"
STACK="scenes/stack.yaml"
for name in "$@"; do
    case $name in
    incline)
        REPEAT=$REPEAT THREADS=$OMP_NUM_THREADS bench/accuracy_time.sh "$BUILD" "$OUT/incline"
        for c in accelerating decelerating; do
            publish "incline_$c" "$OUT/incline/tetrahedron_$c"
        done
        ;;
    friction_acc | friction_dec)
        case $name in friction_acc) c=accelerating ;; *) c=decelerating ;; esac
        sweep "$name" "scenes/validation/tetrahedron_$c.yaml" --analytic incline \
            --vary effects.friction=improved,projection
        ;;
    dt_safety)
        # shellcheck disable=SC2086 # $DRAPE is a scene and its --set
        sweep dt_safety $DRAPE --vary time.dt_safety=0.9,0.5,0.25,0.125 \
            --vary time.step_limit=undamped,damped --reference time.step_limit=undamped
        ;;
    cg_tolerance)
        # shellcheck disable=SC2086
        sweep cg_tolerance $DRAPE --vary time.cg_tolerance=1e-1,1e-2,1e-3,1e-4,1e-5
        ;;
    resolution)
        # shellcheck disable=SC2086
        sweep resolution $DRAPE --vary 'cloths.0.grid.resolution=[10,10],[20,20],[40,40],[80,80]'
        cost_exponent
        ;;
    collision_steps)
        sweep collision_steps $STACK --vary time.collision_steps=1,2,4,16,64
        ;;
    repulsion)
        sweep repulsion $STACK --vary self_collision.thickness=0.0025,0.005,0.01,0.02 \
            --vary self_collision.stiffness=10,30,100 --reference self_collision.stiffness=30
        ;;
    zone_iterations)
        sweep zone_iterations $STACK --vary self_collision.zone_iterations=1,2,4,8,16
        ;;
    twist)
        sweep twist scenes/figures/twist.yaml --vary time.collision_steps=1,4,16
        ;;
    scheme)
        sweep scheme $STACK --vary self_collision.scheme=fixed,rewind \
            --reference self_collision.scheme=fixed
        ;;
    *)
        # shellcheck disable=SC2086 # $ALL is a list
        die "no sweep '$name' (there are: $(printf '%s ' $ALL))"
        ;;
    esac
done
echo "wrote $GALLERY/"
