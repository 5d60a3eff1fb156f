#!/bin/sh
# bench/scaling.sh [BUILD_DIR] [RANKS...]: strong scaling, the paper's Fig. 16.
#
# Runs scenes/scaling.yaml under mpirun with each rank count N (default
# "1 2", or $RANKS), REPEAT times each (default 3), and takes the median of
# simulation seconds per simulated frame from summary.json. Writes
# out/scaling/scaling.csv, draws gallery/scaling.png with bench_scaling_plot
# and prints a Markdown table. BUILD_DIR (default build) should be a Release
# build. Extra arguments for clothsim run go in $CLOTHSIM_ARGS (e.g.
# "--frames 2" for a quick try), extra ones for mpirun in $MPIRUN_ARGS.
set -eu
cd "$(dirname "$0")/.."
BUILD=${1:-build}
[ $# -gt 0 ] && shift
# shellcheck disable=SC2086 # $RANKS is a list
[ $# -gt 0 ] || set -- ${RANKS:-1 2}
REPEAT=${REPEAT:-3}
SCENE=scenes/scaling.yaml
OUT=out/scaling
CSV=$OUT/scaling.csv
PNG=gallery/scaling.png

die() { echo "scaling.sh: $*" >&2; exit 1; }
for tool in "$BUILD/clothsim" "$BUILD/bench_scaling_plot"; do
    [ -x "$tool" ] || die "no $tool: build first (cmake -S . -B $BUILD -DCMAKE_BUILD_TYPE=Release && cmake --build $BUILD)"
done
command -v mpirun >/dev/null || die "no mpirun: install openmpi-bin (scripts/install-deps.sh)"
command -v python3 >/dev/null || die "no python3 (scripts/install-deps.sh installs it)"
case $REPEAT in '' | *[!0-9]* | 0) die "REPEAT must be a whole number >= 1, not '$REPEAT'" ;; esac
for n in "$@"; do
    case $n in '' | *[!0-9]* | 0) die "a rank count must be a whole number >= 1, not '$n'" ;; esac
done

# Open MPI in this container: running as root is refused unless allowed, and
# the shared-memory transport's single-copy mode needs ptrace rights it lacks.
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
export OMPI_MCA_btl_vader_single_copy_mechanism=none

# One finished run's summary.json -> "SECONDS_PER_FRAME PARTICLES TRIANGLES",
# or a message and exit status 1.
read_summary() {
    python3 - "$1" "$2" <<'EOF'
import json, sys
path, ranks = sys.argv[1], int(sys.argv[2])
def fail(what):
    sys.exit("scaling.sh: %s: %s" % (path, what))
try:
    with open(path) as f:
        s = json.load(f)
except (OSError, ValueError) as e:
    fail("cannot read: %s" % e)
if s.get("status") != "ok":
    fail('status is "%s", not "ok"' % s.get("status"))
if "ranks" in s and s["ranks"] != ranks:
    fail("ran on %s ranks, not the %d asked of mpirun" % (s["ranks"], ranks))
if "ranks" not in s and ranks > 1:
    print("scaling.sh: warning: %s has no \"ranks\": this clothsim is not parallel, "
          "mpirun ran %d separate copies" % (path, ranks), file=sys.stderr)
frames = len(s["frames"])
if frames < 1:
    fail("no frame was simulated")
print("%.9g %d %d" % (s["simulation_seconds"] / frames, s["particles"], s["triangles"]))
EOF
}

median() { sort -g | awk '{ v[NR] = $1 } END { print NR % 2 ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }

mkdir -p "$OUT" gallery
rows=$OUT/rows.tmp
: >"$rows"
for n in "$@"; do
    dir=$OUT/np$n
    mkdir -p "$dir"
    times=""
    k=1
    while [ "$k" -le "$REPEAT" ]; do
        echo "scaling.sh: $n rank(s), run $k of $REPEAT" >&2
        log=$dir/run$k.log
        # shellcheck disable=SC2086
        if ! mpirun --oversubscribe ${MPIRUN_ARGS:-} -np "$n" "$BUILD/clothsim" run "$SCENE" \
            -o "$dir" --quiet ${CLOTHSIM_ARGS:-} >"$log" 2>&1; then
            tail -n 20 "$log" >&2
            die "the run with $n rank(s) failed (whole output in $log)"
        fi
        got=$(read_summary "$dir/summary.json" "$n") || exit 1
        spf=${got%% *}
        sizes=${got#* }
        times="$times $spf"
        k=$((k + 1))
    done
    # shellcheck disable=SC2086 # $times is a list
    echo "$n $(printf '%s\n' $times | median) $times" >>"$rows"
done

particles=${sizes% *}
triangles=${sizes#* }
{
    printf '# title: clothsim strong scaling: %s, %s particles, %s triangles, %s cores\n' \
        "$SCENE" "$particles" "$triangles" "$(nproc)"
    echo "# median of $REPEAT runs each; simulation seconds per simulated frame"
    echo "ranks,seconds_per_frame"
    awk '{ printf "%d,%.6g\n", $1, $2 }' "$rows"
} >"$CSV"
"$BUILD/bench_scaling_plot" "$CSV" "$PNG"

echo
echo "$SCENE: $particles particles, $triangles triangles; median of $REPEAT runs"
echo
# speedup from the first (smallest) rank count, as bench_scaling_plot does
sort -n "$rows" | awk '
    NR == 1 { base = $1 * $2 }
    { n[NR] = $1; s[NR] = $2 }
    END {
        print "| ranks | s/frame | speedup | efficiency |"
        print "|------:|--------:|--------:|-----------:|"
        for (i = 1; i <= NR; i++)
            printf "| %d | %.3f | %.2f | %.0f%% |\n", n[i], s[i], base / s[i], 100 * base / s[i] / n[i]
    }'
echo
echo "wrote $CSV and $PNG"
rm -f "$rows"
