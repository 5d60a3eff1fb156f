#!/bin/sh
# cli_mesh_bad.sh CLOTHSIM_EXE SOURCE_DIR: no mesh file crashes or hangs a
# command. Every file of tests/data/bad_meshes/ through
# `clothsim mesh-info` (exit 2, one line naming the file and what is
# wrong), bad files as a scene's body and cloth, a binary PLY that assimp
# 5.2 misread read right by every reader, the units warning, and a cloth
# without triangles written and read back as a point cloud.
set -eu

NAME=cli_mesh_bad
. "$2/tests/harness.sh"
BAD="$2/tests/data/bad_meshes"
[ -r "$BAD/ply_no_end_header.ply" ] || fail "tests/data/bad_meshes is missing (looked in $BAD)"

# bad FILE TEXT: mesh-info exits 2 with one line naming FILE and saying TEXT
bad() {
    run 2 mesh-info "$BAD/$1"
    err_has "^clothsim mesh-info: .*$1"
    err_has "$2"
    [ "$(grep -c . err.txt)" -eq 1 ] || fail "mesh-info $1: more than one line on stderr"
}

bad ply_list_count_255.ply 'PLY face 0 has a list of 255 entries'
bad ply_list_count_255_ascii.ply "list of '255' entries but 3 values follow"
bad ply_flipped_face_bytes.ply 'refers to vertex 65280, but the file has 4 vertices'
bad ply_no_end_header.ply 'no end_header line'
bad ply_1e20_vertices.ply "count '100000000000000000000' is not a whole number"
bad ply_2e31_vertices.ply "promises 2147483648 'vertex' elements"
bad ply_4e9_faces.ply "promises 4000000000 'face' elements"
bad ply_4e9_list_entries.ply 'a list of 4000000000 entries'
bad ply_4e9_list_entries_ascii.ply "a list of '4000000000' entries"
bad ply_index_2e9.ply 'refers to vertex 2000000000'
bad ply_index_minus5.ply 'refers to vertex -5'
bad ply_tristrips.ply 'triangle strips'
bad ply_mostly_unused.ply 'most of .* was not understood'
bad obj_long_number.obj 'a number of more than 100 digits'

# the same reader behind the other commands
run 2 levelset "$BAD/ply_flipped_face_bytes.ply" -o x.vdb --voxel 0.1
err_has 'refers to vertex 65280'
run 2 intersections "$BAD/ply_index_minus5.ply"
err_has 'refers to vertex -5'

# a face of 300,000 corners: refused at once, not minutes of triangulation
python3 -c '
import math
n = 300000
with open("huge_face.obj", "w") as f:
    for i in range(n):
        f.write("v %.6f %.6f 0\n" % (math.cos(2 * math.pi * i / n), math.sin(2 * math.pi * i / n)))
    f.write("f " + " ".join(str(i + 1) for i in range(n)) + "\n")
'
start=$(date +%s)
run 2 mesh-info huge_face.obj
err_has 'has 300000 corners; at most 10000 are read'
[ $(($(date +%s) - start)) -lt 60 ] || fail "the 300,000-corner face took $(($(date +%s) - start)) s"

# a bad file as a body or a cloth: the scene's line and key, exit 2
cat >body.yaml <<YAML
cloths: [{grid: {resolution: [4, 4], center: [0, 1, 0]}}]
bodies:
  - shape: mesh
    mesh: {file: $BAD/ply_flipped_face_bytes.ply}
YAML
run 2 run body.yaml -o out_body
err_has '^clothsim: body\.yaml:4: bodies\[0\]\.mesh\.file: .*ply_flipped_face_bytes\.ply: PLY face 0 refers to vertex 65280'
cat >cloth.yaml <<YAML
cloths:
  - mesh: {file: $BAD/ply_no_end_header.ply}
YAML
run 2 run cloth.yaml -o out_cloth
err_has 'cloths\[0\]\.mesh\.file: .*no end_header line'

# assimp 5.2 misread a binary PLY whose data begins with 0x0A
run 0 mesh-info "$BAD/ply_data_starts_with_lf.ply"
grep -q "result:    3 vertices, 1 triangles" out.txt || fail "ply_data_starts_with_lf.ply misread"
grep -q "size:      2 x 1 x 0 m" out.txt || fail "ply_data_starts_with_lf.ply: wrong coordinates"
run 0 intersections "$BAD/ply_data_starts_with_lf.ply"

# an STL in millimetres: a warning that says how to set units
run 0 mesh-info "$BAD/stl_in_millimetres.stl"
err_has 'warning: .*stl_in_millimetres\.stl: the mesh is 150 m across.*set units: mm'
run 0 mesh-info "$BAD/stl_in_millimetres.stl" --units mm
! grep -q warning err.txt || fail "--units mm still warned"

# a cloth without triangles: a point cloud in every format, read back
for format in ply obj glb; do
    run 0 run "$2/scenes/validation/particle_accelerating.yaml" -o "pa_$format" --frames 2 -q \
        --format "$format"
    frame="pa_$format/frames/frame_0002.$format"
    [ -s "$frame" ] || fail "particle_accelerating wrote no $frame"
    run 0 intersections "$frame"
    grep -q '^0 intersecting triangle pairs' out.txt || fail "$frame not read back"
done
head -c 200 pa_ply/frames/frame_0002.ply | grep -q '^element vertex 1' || fail "no vertex element"
! head -c 200 pa_ply/frames/frame_0002.ply | grep -q '^element face' ||
    fail "a point-cloud PLY with faces"

echo "cli_mesh_bad: all checks passed"
