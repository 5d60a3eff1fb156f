#!/bin/sh
# cli_mesh.sh CLOTHSIM_EXE SOURCE_DIR: mesh files and level sets from the
# command line: `clothsim mesh-info`, `clothsim levelset`, their
# errors (status 2, one clear line), and the shipped bunny scene, whose
# frames must stay clear of the body (summary.json's body_penetration_max).
# The meshes are in the repository's assets/ folder; without them this
# test fails.
set -eu

NAME=cli_mesh
. "$2/tests/harness.sh"
ASSETS="$2/assets"
[ -r "$ASSETS/ico4.obj" ] || fail "the repository's assets/ folder is missing (looked in $ASSETS)"

# --- mesh-info: what import sees
run 0 mesh-info "$ASSETS/human.dae"
grep -q "format:    Collada" out.txt || fail "mesh-info: no format"
grep -q "'human-baseObject': mesh 0" out.txt || fail "mesh-info: no node tree"
grep -q "result:    14444 vertices, 28796 triangles, 5 parts" out.txt || fail "mesh-info: counts"
grep -q "80 boundary edges in 4 loops" out.txt || fail "mesh-info: topology"
run 0 mesh-info "$ASSETS/human.dae" --node human-baseObject
grep -q "closed:    yes" out.txt || fail "mesh-info --node: the body alone is closed"
run 0 mesh-info "$ASSETS/Spider_binary.stl"
grep -q "dropped 56 zero-area" out.txt || fail "mesh-info: repairs"
grep -q "10 edges with inconsistent orientation" out.txt || fail "mesh-info: orientation"
run 0 mesh-info "$ASSETS/spider.fbx"
grep -q "1 cm per unit" out.txt || fail "mesh-info: FBX units"

run 2 mesh-info missing.obj
err_has '^clothsim mesh-info: cannot read missing\.obj: No such file or directory$'
echo "not a mesh" >notes.xyz123
run 2 mesh-info notes.xyz123
err_has 'No suitable reader'
printf 'v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n' >nan.obj
run 2 mesh-info nan.obj
err_has 'vertex 1 has a non-finite coordinate'
run 2 mesh-info "$ASSETS/ico4.obj" --node lid
err_has "has no node or mesh named 'lid'"
run 1 mesh-info
err_has 'usage'
run 1 mesh-info "$ASSETS/ico4.obj" --units furlong
run 0 help mesh-info

# --- levelset: a .vdb outside any scene
run 0 levelset "$ASSETS/ico4.obj" -o ico4.vdb --voxel 0.1
[ -s ico4.vdb ] || fail "levelset wrote no file"
grep -q "^grid:      .* voxels, bounds" out.txt || fail "levelset: no grid line"
grep -q "^active:    [0-9]* voxels" out.txt || fail "levelset: no voxel count"
grep -q "MB in memory" out.txt || fail "levelset: no memory"
run 0 levelset "$ASSETS/stanford-bunny.obj" -o bunny.vdb --voxel 0.004 --interior band
grep -q "closed 5 holes with fans" out.txt || fail "levelset: holes not closed"
run 2 levelset "$ASSETS/ico4.obj" -o tiny.vdb --voxel 1e-6
err_has 'would need about .* of memory.* but .* is available'
[ ! -e tiny.vdb ] || fail "an absurd voxel size wrote a file"
run 2 levelset "$ASSETS/ico4.obj" -o big.vdb --voxel 5
err_has 'at most a quarter'
run 2 levelset missing.stl -o x.vdb
run 1 levelset "$ASSETS/ico4.obj"
err_has 'no output file'
run 1 levelset "$ASSETS/ico4.obj" -o x.vdb --band 0

# --- a scene with a missing mesh: status 2, FILE:LINE: KEY
cat >bad.yaml <<'YAML'
cloths: [{grid: {resolution: [4, 4], center: [0, 1, 0]}}]
bodies:
  - shape: mesh
    mesh: {file: nowhere/thing.obj}
YAML
run 2 run bad.yaml
err_has '^clothsim: bad\.yaml:4: bodies\[0\]\.mesh\.file: cannot read \./nowhere/thing\.obj: No such file or directory$'
[ ! -e out ] || fail "a bad scene wrote output"

# --- the shipped bunny scene, coarse: its frames stay out of the body. The
# penetration is measured on the cloth's surface (triangle centroids and edge
# midpoints too), so the collision offset must be about half an edge (7.5 cm
# here); without it the body pokes through between vertices, and the
# measure must see that
run 0 run "$2/scenes/bunny_drape.yaml" -o bare --frames 12 -q \
    --set 'cloths.0.grid.resolution=[16,16]' --set bodies.0.collision_offset=0
python3 - bare/summary.json <<'PY' || fail "bunny scene: pokes between vertices not measured"
import json, sys
worst = max(f["body_penetration_max"] for f in json.load(open(sys.argv[1]))["frames"])
assert worst > 0.005, "penetration %g m" % worst
PY
run 0 run "$2/scenes/bunny_drape.yaml" -o bunny --frames 12 -q \
    --set 'cloths.0.grid.resolution=[16,16]' --set bodies.0.collision_offset=0.04
err_has "bodies\[0\] 'bunny': level set .* voxels"
err_has "warning: bodies\[0\] 'bunny': the mesh is not closed"
python3 - bunny/summary.json <<'PY' || fail "bunny scene: cloth inside the body"
import json, sys
s = json.load(open(sys.argv[1]))
frames = s["frames"]
assert s["status"] == "ok" and len(frames) == 12, s["status"]
assert sum(f["body_contacts"] for f in frames) > 0, "the cloth never touched the bunny"
worst = max(f["body_penetration_max"] for f in frames)
assert worst < 1e-4, "penetration %g m" % worst
PY

echo "cli_mesh: all checks passed"
