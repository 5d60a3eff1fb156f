#!/bin/sh
# gallery/make.sh [gallery|test]: remakes the gallery from the scenes and
# benchmarks (Release build), then every paper figure of scenes/figures/
# with gallery/figure.sh: at the gallery size (the default; hours of CPU),
# or at the scenes' committed test size with `test` (which leaves
# gallery/figures/ alone). gallery/README.md says what made each picture.
# With FIGURE_SIM_ONLY=1 it only runs the figures and gathers Table 3
# (out/figures/table3.md), e.g. `FIGURE_SIM_ONLY=1 gallery/make.sh test`.
set -eu
cd "$(dirname "$0")/.."
MODE=${1:-gallery}
case $MODE in
test | gallery) ;;
*)
    echo "usage: gallery/make.sh [gallery|test]" >&2
    exit 1
    ;;
esac
scripts/install-deps.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j"$(nproc)"
# FIGURE_SIM_ONLY=1: Table 3 alone (the figures' runs, no pictures)
if [ -z "${FIGURE_SIM_ONLY:-}" ]; then
    bench/accuracy_sweeps.sh build
    gallery/render.sh build
    gallery/selfcol.sh build
    # strong scaling at 1 and 2 ranks (more where the machine has the cores)
    bench/scaling.sh build 1 2
fi

# The paper's figures, one command each; a figure that fails is reported at
# the end and does not stop the others.
failed=
ran=
for scene in scenes/figures/*.yaml; do
    [ -f "$scene" ] || continue
    name=$(basename "$scene" .yaml)
    if BUILD=build gallery/figure.sh "$name" "$MODE"; then
        ran="$ran $name"
    else
        failed="$failed $name"
    fi
done

# Table 3: a row per figure made now (out/figures/table3.md; in gallery mode
# also gallery/figures/table3.md).
# shellcheck disable=SC2086 # $ran is a list of names
python3 - "$MODE" $ran <<'EOF'
import os, sys
mode = sys.argv[1]
rows = head = []
for name in sys.argv[2:]:
    lines = open("out/figures/%s/table3.md" % name).read().splitlines()
    head, rows = lines[:2], rows + lines[2:]
if rows:
    text = "\n".join(head + rows) + "\n"
    open("out/figures/table3.md", "w").write(text)
    if mode == "gallery" and not os.environ.get("FIGURE_SIM_ONLY"):
        os.makedirs("gallery/figures", exist_ok=True)
        open("gallery/figures/table3.md", "w").write(text)
    print(text, end="")
EOF
if [ -n "$failed" ]; then
    echo "gallery/make.sh: these figures failed:$failed" >&2
    exit 1
fi
