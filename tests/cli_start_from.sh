#!/bin/sh
# cli_start_from.sh CLOTHSIM_EXE SOURCE_DIR: `clothsim run --start-from RUN`
# carries a coarse run's state and frames onto the same cloth at twice the
# resolution: every fine vertex on a coarse vertex or edge has the coarse
# run's position there (the map is the coarse surface, exactly), the start
# is intersection-free, the run simulates on from it on one rank and on two,
# and the folder resumes into the bits of a run never interrupted. A cloth
# of another rest shape, scripted vertices the run did not script, the
# run's own folder as -o, too few frames and --resume beside it are
# refused before any frame of -o DIR is removed.
set -eu

NAME=cli_start_from
. "$2/tests/harness.sh"
SRC=$2
TWIST="$SRC/scenes/figures/twist.yaml"
MPI_ASAN_OPTIONS=detect_leaks=0 # as cli_resume.sh: cli_mpi checks leaks under mpirun

run 0 run "$TWIST" -o coarse -q --frames 6 --set 'cloths.0.grid.resolution=[16,8]'
FINE="cloths.0.grid.resolution=[32,16]"
run 0 run "$TWIST" -o fine -q --frames 8 --set "$FINE" --start-from coarse

python3 - coarse fine <<'EOF' || fail "the carried frames"
import json, struct, sys
coarse, fine = sys.argv[1], sys.argv[2]

def vertices(path):
    data = open(path, "rb").read()
    head, body = data.split(b"end_header\n", 1)
    lines = head.decode().splitlines()
    assert "format binary_little_endian 1.0" in lines, path
    nv = int([l for l in lines if l.startswith("element vertex")][0].split()[2])
    props = []
    for l in lines:
        if l.startswith("element face"):
            break
        if l.startswith("property"):
            props.append(l.split()[1])
    fmt = "<" + "".join("f" if p in ("float", "float32") else "d" for p in props)
    stride = struct.calcsize(fmt)
    return [struct.unpack_from(fmt, body, i * stride)[:3] for i in range(nv)]

recs = [json.loads(l) for l in open(fine + "/frames.jsonl")]
assert [r["frame"] for r in recs] == list(range(1, 9)), [r["frame"] for r in recs]
for r in recs[:6]:
    assert r.get("resampled_from") == coarse and r["steps"] == 0, r
assert recs[5]["intersections"] == 0, recs[5]
for r in recs[6:]:
    assert "resampled_from" not in r and r["steps"] > 0, r
    assert r["intersections"] == 0 and r["script_lag"] == 0, r
s = json.load(open(fine + "/summary.json"))
assert s["status"] == "ok" and s["carried_frames"] == 6 and s["frames_written"] == 9, s
assert s["particles"] == 33 * 17, s["particles"]

# frame 3 comes from the coarse frame file, frame 6 from the coarse state
for f in (3, 6):
    name = "/frames/frame_%04d.ply" % f
    c, x = vertices(coarse + name), vertices(fine + name)
    assert len(c) == 17 * 9 and len(x) == 33 * 17, (len(c), len(x))
    worst = 0.0
    moved = max(abs(c[j * 17 + i][1]) + abs(c[j * 17 + i][2] - (j / 8 - 0.5) * 0.5)
                for j in range(9) for i in range(17))
    assert moved > 0.01, "frame %d: the coarse cloth has not moved (%g m)" % (f, moved)
    for j in range(9):
        for i in range(17):
            a = c[j * 17 + i]
            on = x[(2 * j) * 33 + 2 * i]
            worst = max(worst, max(abs(p - q) for p, q in zip(a, on)))
            if i < 16: # the fine vertex halfway along a coarse edge
                b = c[j * 17 + i + 1]
                mid = x[(2 * j) * 33 + 2 * i + 1]
                worst = max(worst, max(abs((p + q) / 2 - m) for p, q, m in zip(a, b, mid)))
    # frames hold 32-bit floats: a few of their units at 1 m
    assert worst <= 1e-6, "frame %d: fine and coarse differ by %g m" % (f, worst)
EOF

# resumed after frame 7 into the bits of the run to 8 never interrupted
run 0 run "$TWIST" -o part -q --frames 7 --set "$FINE" --start-from coarse
run 0 run part --resume -q --frames 8
for k in 6 7 8; do
    f=$(printf 'frames/frame_%04d.ply' "$k")
    cmp -s "fine/$f" "part/$f" || fail "frame $k of the resumed run differs"
done
grep -Eq '"carried_frames":[[:space:]]*6' part/summary.json || fail "the resumed summary lost the carried frames"

# two ranks take the carried state (at rest instead, they would differ by
# centimetres in frame 7); rank counts agree within round-off
mpi_run 0 2 run "$TWIST" -o fine2 -q --frames 7 --set "$FINE" --start-from coarse
python3 - fine fine2 <<'EOF' || fail "two ranks"
import struct, sys
def floats(path):
    data = open(path, "rb").read()
    head, body = data.split(b"end_header\n", 1)
    nv = int([l for l in head.decode().splitlines() if l.startswith("element vertex")][0].split()[2])
    return struct.unpack_from("<%df" % (3 * nv), body)
a = floats(sys.argv[1] + "/frames/frame_0007.ply")
b = floats(sys.argv[2] + "/frames/frame_0007.ply")
worst = max(abs(p - q) for p, q in zip(a, b))
assert worst < 1e-4, "frame 7 on two ranks differs by %g m" % worst
EOF

# refusals, each before the output folder is touched
run 2 run "$TWIST" -o fine -q --frames 8 --set "$FINE" --set 'cloths.0.grid.size=[1.0,0.6]' \
    --start-from coarse
err_has "at rest is not the run's cloth at rest"
[ -f fine/frames/frame_0008.ply ] || fail "a refused start removed the frames of -o DIR"
run 2 run "$TWIST" -o coarse -q --frames 8 --set "$FINE" --start-from coarse
err_has "is the output folder"
[ -f coarse/frames/frame_0006.ply ] || fail "the run to start from lost its frames"
run 2 run "$TWIST" -o other -q --frames 5 --set "$FINE" --start-from coarse
err_has "ends at frame 6.*give --frames 6 or more"
run 2 run "$TWIST" -o other -q --frames 8 --set "$FINE" --start-from coarse \
    --set 'cloths.0.scripts.0.select.box.max=[-0.46,1,1]'
err_has "scripted particle [0-9]+ of this scene is .* from where its script puts it"
run 2 run "$TWIST" -o other -q --frames 8 --start-from fine/frames
err_has "no run folder"
run 1 run fine --resume --start-from coarse
err_has "give one of them"
echo "$NAME: ok"
