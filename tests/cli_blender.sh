#!/bin/sh
# cli_blender.sh CLOTHSIM_EXE SOURCE_DIR: Blender opens what `run` writes
# with output.pc2: the rest pose OBJ imported without axis conversion, a
# Mesh Cache modifier (PC2) on it, the depsgraph evaluated at Blender
# frames 1 and 4 (tests/blender_pc2.py); the vertices must be the frame
# files' frames 1 and 4, the same float32 values, in the same order.
# Skipped (77) where `blender` is not on PATH (Debian's blender package is
# too large for CI; install it to run this).
set -eu

NAME=cli_blender
. "$2/tests/harness.sh"

command -v blender >/dev/null 2>&1 || {
    echo "$NAME: SKIP: blender is not on PATH (apt-get install blender to run this test)"
    exit 77
}
run 0 run "$2/scenes/drape.yaml" -o drape -q --frames 4 \
    --set 'cloths.0.grid.resolution=[12,12]' --set output.pc2=true --set output.usd=false
blender -b --factory-startup \
    --python "$2/tests/blender_pc2.py" -- drape/pc2/sheet.obj drape/pc2/sheet.pc2 \
    blender.json 1 4 >blender.txt 2>&1 || { cat blender.txt >&2; fail "blender failed"; }
[ -s blender.json ] || { cat blender.txt >&2; fail "blender wrote no blender.json"; }
python3 - drape blender.json <<'PY' || fail "Blender's vertices differ from the frame files"
import json, struct, sys
d, result = sys.argv[1], json.load(open(sys.argv[2]))

def ply_points(path):
    data = open(path, "rb").read()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode("latin-1").split("\n")
    nv = int(next(l for l in header if l.startswith("element vertex")).split()[2])
    props = [l.split() for l in header if l.startswith("property float")]
    # assimp writes x y z (and normals) as the vertex's leading floats
    assert [p[2] for p in props[:3]] == ["x", "y", "z"], props
    stride = 4 * len([p for p in props if p[2] in ("x", "y", "z", "nx", "ny", "nz")])
    return [struct.unpack_from("<fff", data, end + v * stride) for v in range(nv)]

identity = [[1.0 if i == j else 0.0 for j in range(4)] for i in range(4)]
assert result["matrix_world"] == identity, result["matrix_world"]
for f, points in sorted(result["frames"].items()):
    ref = ply_points(f"{d}/frames/frame_{int(f):04d}.ply")
    assert len(points) == len(ref) == result["vertices"], (len(points), len(ref))
    worst = max(abs(a - b) for p, q in zip(points, ref) for a, b in zip(p, q))
    same = all(struct.pack("<fff", *p) == struct.pack("<fff", *q) for p, q in zip(points, ref))
    print(f"Blender frame {f}: {len(points)} vertices, largest difference {worst:g} m, "
          f"{'bit-identical' if same else 'NOT identical'} to frame_{int(f):04d}.ply")
    assert same
PY
echo "$NAME: ok"
