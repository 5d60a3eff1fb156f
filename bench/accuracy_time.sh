#!/bin/sh
# bench/accuracy_time.sh [BUILD_DIR] [OUT_DIR]: what accuracy costs in time
# on the analytic incline (Figs. 7, 8): `clothsim sweep --analytic incline`
# on the damped tetrahedron of scenes/validation, accelerating (mu = 0.6)
# and decelerating (mu = 0.9, v0 = 1 m/s), every combination of the step
# (time.dt_safety), the CG tolerance (time.cg_tolerance) and the friction
# method (effects.friction: improved, projection = the previous method).
#
# Each scene's sweep goes to OUT_DIR/tetrahedron_{accelerating,decelerating}/
# (default OUT_DIR: out/accuracy_time): sweep.csv and sweep.md (analytic_m:
# the largest distance of the centre of mass from the analytic one over
# 1 s), sweep.png (analytic_m against wall seconds), trajectory.png and
# cumulative_time.png. REPEAT=N (default 1) runs each N times (sweep
# --repeat: wall_s the median; the errors do not change, the runs are
# deterministic). BUILD_DIR (default build) should be a Release build.
#
# The runs take $THREADS OpenMP threads each (default 1: on a shared
# machine a spinning thread team measures the neighbours, not clothsim).
set -eu
cd "$(dirname "$0")/.."
BUILD=${1:-build}
OUT=${2:-out/accuracy_time}
REPEAT=${REPEAT:-1}
export OMP_NUM_THREADS="${THREADS:-1}"
DT=${DT_SAFETY:-1,0.5,0.25,0.1}
TOL=${CG_TOLERANCE:-1e-1,1e-2,1e-3,1e-5}

die() { echo "accuracy_time.sh: $*" >&2; exit 1; }
[ -x "$BUILD/clothsim" ] ||
    die "no $BUILD/clothsim: build first (cmake -S . -B $BUILD -DCMAKE_BUILD_TYPE=Release && cmake --build $BUILD)"
case $REPEAT in '' | *[!0-9]* | 0) die "REPEAT must be a whole number >= 1, not '$REPEAT'" ;; esac

for case in accelerating decelerating; do
    dir=$OUT/tetrahedron_$case
    echo "accuracy_time.sh: tetrahedron_$case -> $dir" >&2
    rm -rf "$dir"
    "$BUILD/clothsim" sweep "scenes/validation/tetrahedron_$case.yaml" --analytic incline \
        --vary "time.dt_safety=$DT" --vary "time.cg_tolerance=$TOL" \
        --vary effects.friction=improved,projection --repeat "$REPEAT" -o "$dir" --quiet
done
echo "wrote $OUT/tetrahedron_accelerating and $OUT/tetrahedron_decelerating"
