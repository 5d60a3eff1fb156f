#!/bin/sh
# cli_pc2.sh CLOTHSIM_EXE SOURCE_DIR: `run` with output.pc2 and `export
# DIR --format pc2` write per cloth DIR/pc2/NAME.pc2, Blender's point
# cache, whose header is right and whose every float32 is bit for bit the
# frame files' (read here from the PLY frames), beside NAME.obj, the rest
# pose: frame 0's positions as the same float32 values, and the scene's
# triangles in the cache's point order. A new run into the folder removes
# them.
set -eu

NAME=cli_pc2
. "$2/tests/harness.sh"

# compare DIR NFRAMES NAME:FRAMEPART...: each cloth's cache and rest pose
# against the frames (FRAMEPART "" for frame_NNNN.ply)
compare() {
    python3 - "$@" <<'EOF' || fail "the point caches differ from the frame files"
import struct, sys
d, nframes, clothes = sys.argv[1], int(sys.argv[2]), sys.argv[3:]

def ply_xyz(path):
    """The x, y, z float32 of each vertex as bytes, and the faces."""
    data = open(path, "rb").read()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode("latin-1").split("\n")
    assert "format binary_little_endian 1.0" in header, path
    sizes = {"float": 4, "uchar": 1, "int": 4, "uint": 4, "double": 8}
    props, nv, elements = [], 0, []
    for line in header:
        w = line.split()
        if w[:1] == ["element"]:
            elements.append((w[1], int(w[2])))
        elif w[:1] == ["property"] and elements[-1][0] == "vertex":
            props.append((w[2], sizes[w[1]]))
    assert elements[0][0] == "vertex", path
    nv = elements[0][1]
    stride = sum(s for _, s in props)
    off = {}
    o = 0
    for name, s in props:
        off[name] = o
        o += s
    out = bytearray()
    for v in range(nv):
        base = end + v * stride
        for k in "xyz":
            out += data[base + off[k]:base + off[k] + 4]
    return bytes(out), nv

for item in clothes:
    name, part = item.split(":")
    pc2 = open(f"{d}/pc2/{name}.pc2", "rb").read()
    sig, version, npoints, start, rate, nsamples = struct.unpack("<12siiffi", pc2[:32])
    assert sig == b"POINTCACHE2\0" and version == 1, (sig, version)
    assert (start, rate, nsamples) == (0.0, 1.0, nframes), (start, rate, nsamples)
    assert len(pc2) == 32 + 12 * npoints * nsamples, (len(pc2), npoints, nsamples)
    for f in range(nframes):
        suffix = f".{part}" if part else ""
        xyz, nv = ply_xyz(f"{d}/frames/frame_{f:04d}{suffix}.ply")
        assert nv == npoints, (name, f, nv, npoints)
        sample = pc2[32 + 12 * npoints * f:32 + 12 * npoints * (f + 1)]
        assert sample == xyz, f"{name}: sample {f} is not the frame file's float32 values"
        if f == 0:
            rest = [l.split() for l in open(f"{d}/pc2/{name}.obj")]
            v = [struct.pack("<fff", *map(float, l[1:4])) for l in rest if l[:1] == ["v"]]
            faces = [l for l in rest if l[:1] == ["f"]]
            assert b"".join(v) == xyz, f"{name}: the rest pose is not frame 0"
            assert all(1 <= int(i) <= nv for l in faces for i in l[1:]), name
            print(f"{name}: {npoints} points x {nsamples} samples bit-exact; rest pose "
                  f"{len(v)} vertices = frame 0, {len(faces)} triangles")
EOF
}

cat >two.yaml <<'YAML'
name: two
time: {fps: 25, frames: 3}
cloths:
  - name: top sheet
    grid: {size: [0.5, 0.5], resolution: [5, 5], center: [0, 1, 0]}
  - name: under
    grid: {size: [0.4, 0.4], resolution: [3, 4], center: [0, 0.5, 0]}
bodies:
  - {name: ground, shape: plane}
YAML
run 0 run two.yaml -o two -q --set output.pc2=true --set output.usd=false
grep -q 'point caches and their rest poses: two/pc2/' out.txt || fail "run does not name pc2/"
[ -e two/cloth.usda ] && fail "output.usd=false still wrote cloth.usda"
ls two/pc2/*.tmp >/dev/null 2>&1 && fail "temporary files left in two/pc2/"
compare two 4 top_sheet:top_sheet under:under >cmp.txt
cat cmp.txt
# a new run into the folder takes the old caches away with the old frames
cp -r two two_again
run 0 run two.yaml -o two_again -q --frames 1
[ -z "$(ls two_again/pc2)" ] || fail "a new run left the caches of the last: $(ls two_again/pc2)"
[ -s two_again/cloth.usda ] || fail "no two_again/cloth.usda"

# the drape, written by export after the run (output.pc2 off by default)
run 0 run "$2/scenes/drape.yaml" -o drape -q --frames 3 --set 'cloths.0.grid.resolution=[12,12]'
[ -e drape/pc2 ] && fail "output.pc2 is on by default"
run 0 export drape --format pc2
grep -q '^wrote drape/pc2/sheet.pc2 (4 samples from frame 0) and its rest pose drape/pc2/sheet.obj' \
    out.txt || fail "export does not say what it wrote"
compare drape 4 sheet: >cmp.txt
cat cmp.txt
echo "$NAME: ok"
