#!/bin/sh
# bench/twist_state.sh [BUILD_DIR] [OUT]: the tangled state of the
# half-million-triangle twist that bench/paper_scale.py --twist-state
# resumes, made in about half an hour on 2 cores (its three runs took
# 44 s, 5.6 min and 27 min on the 2-vCPU VM of docs/performance.md)
# instead of the hours 42 frames at 1000 x 250 quads would take.
#
# scenes/figures/twist.yaml runs 40 frames (1.67 s: 3.3 relative turns,
# the ends 0.33 m closer, the sheet a rope lying on itself) at 100 x 25
# quads; --start-from carries frame 40 onto 500 x 125 quads (five times
# the quads each way: every fine vertex on the coarse surface), which
# simulates frame 41; that is carried onto 1000 x 250 (twice again), which
# simulates frame 42, relaxing what the carry left. OUT (default
# out/twist_500k) is then a run folder of the 1000 x 250 twist at frame 42,
# its frames 1-41 carried from the coarser runs (their records say
# resampled_from), to resume with --frames 44. The repulsion thickness is
# below half the shortest edge at each size: 1.2, 0.8 and 0.4 mm.
set -eu
cd "$(dirname "$0")/.."
BUILD=${1:-build}
OUT=${2:-out/twist_500k}
C="$BUILD/clothsim"
S=scenes/figures/twist.yaml
WORK="$OUT.steps"
mkdir -p "$WORK"
"$C" run "$S" -o "$WORK/100x25" -q --frames 40 --set 'cloths.0.grid.resolution=[100,25]'
"$C" run "$S" -o "$WORK/500x125" -q --frames 41 --start-from "$WORK/100x25" \
    --set 'cloths.0.grid.resolution=[500,125]' --set self_collision.thickness=0.0008
"$C" run "$S" -o "$OUT" -q --frames 42 --start-from "$WORK/500x125" \
    --set 'cloths.0.grid.resolution=[1000,250]' --set self_collision.thickness=0.0004
echo "twist_state.sh: $OUT holds the 1000 x 250 twist at frame 42 (the coarser runs in $WORK)"
