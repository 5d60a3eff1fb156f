#!/bin/sh
# cli_mpi.sh CLOTHSIM_EXE SOURCE_DIR: `mpirun -np N clothsim run` as a user
# types it (MPIEXEC and Open MPI's container settings come from ctest):
# one set of output files, the same frames as one rank, communication in
# the stage table and per rank in summary.json, one message for bad input.
set -eu

NAME=cli_mpi
. "$2/tests/harness.sh"
SCENES="$2/scenes"
MPIEXEC=${MPIEXEC:-mpirun}


SMALL="--set cloths.0.grid.resolution=[16,16] --frames 3 -q"
# shellcheck disable=SC2086
run 0 run "$SCENES/drape.yaml" -o one $SMALL
# shellcheck disable=SC2086
mpi_run 0 2 run "$SCENES/drape.yaml" -o two $SMALL
grep -q "comm" out.txt || fail "the stage table has no communication column"
grep -q "2 ranks" out.txt || fail "the table does not say how many ranks ran"
[ "$(grep -c '^all stages' out.txt)" -eq 1 ] || fail "the table is printed more than once"
[ ! -e two/frames/frame_0000.ply.tmp ] || fail "a temporary file was left"

python3 - one two <<'EOF' || fail "two ranks do not match one"
import json, struct, sys, os
one, two = sys.argv[1], sys.argv[2]
a, b = json.load(open(one + "/summary.json")), json.load(open(two + "/summary.json"))
def need(cond, what):
    if not cond:
        sys.exit(what)
need(a["ranks"] == 1 and b["ranks"] == 2, "ranks %r and %r" % (a.get("ranks"), b.get("ranks")))
comm = b["communication"]
need(len(comm) == 2 and all(c["bytes_sent"] > 0 and c["messages_sent"] > 0 for c in comm),
     "per-rank communication %r" % comm)
need(all(c["bytes_sent"] == 0 for c in a["communication"]), "one rank sent bytes")
need(any(s["bytes_sent"] > 0 and s["communication_seconds"] >= 0 for s in b["stages"]),
     "no stage sent anything")
need(sorted(os.listdir(one + "/frames")) == sorted(os.listdir(two + "/frames")),
     "different frame files")
for fa, fb in zip(a["frames"], b["frames"]):
    need(fa["cg_iterations"] == fb["cg_iterations"], "CG iterations differ: %r %r" % (fa, fb))

def vertices(path):
    data = open(path, "rb").read()
    head, body = data.split(b"end_header\n", 1)
    lines = head.decode().splitlines()
    nv = int([l for l in lines if l.startswith("element vertex")][0].split()[2])
    props = [l.split() for l in lines if l.startswith("property")]
    sizes = {"float": 4, "double": 8, "float32": 4, "float64": 8}
    first = []
    for p in props: # vertex properties come first
        if p[1] == "list":
            break
        first.append(p)
    fmt = "<" + "".join("f" if sizes[p[1]] == 4 else "d" for p in first[:len(first)])
    stride = struct.calcsize(fmt)
    need("binary_little_endian" in head.decode(), "expected binary PLY")
    return [struct.unpack_from(fmt, body, i * stride)[:3] for i in range(nv)]
for name in sorted(os.listdir(one + "/frames")):
    va, vb = vertices(one + "/frames/" + name), vertices(two + "/frames/" + name)
    need(len(va) == len(vb), name + ": vertex counts differ")
    worst = max(abs(p - q) for u, w in zip(va, vb) for p, q in zip(u, w))
    # frames hold 32-bit floats: within a couple of their units at 1 m
    need(worst <= 1e-6, "%s: vertices differ by %g" % (name, worst))
EOF

# bad input: one message, not one per rank, and the usual status
mpi_run 2 2 run "$SCENES/drape.yaml" -o bad --set time.fps=-1 -q
[ "$(grep -c 'fps' err.txt)" -eq 1 ] || fail "expected one error line about fps"

# self-collision across four ranks: the verifier finds nothing at any frame
mpi_run 0 4 run "$SCENES/stack.yaml" -o stack --frames 6 -q
python3 - stack/summary.json <<'EOF' || fail "stack on four ranks"
import json, sys
s = json.load(open(sys.argv[1]))
assert s["ranks"] == 4, s["ranks"]
assert len(s["communication"]) == 4
assert [f["intersections"] for f in s["frames"]] == [0] * 6, [f["intersections"] for f in s["frames"]]
EOF
echo "$NAME: ok"
