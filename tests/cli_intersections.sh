#!/bin/sh
# cli_intersections.sh CLOTHSIM_EXE SOURCE_DIR: `clothsim intersections`
# counts the intersecting triangle pairs of a mesh file exactly and says so
# by its exit status: 0 clean, 1 intersecting, 2 bad input.
set -eu

NAME=cli_intersections
. "$2/tests/harness.sh"

# Two unit squares (two triangles each) one above the other: no pair meets.
cat >clean.obj <<'OBJ'
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
v 0 0 0.5
v 1 0 0.5
v 1 1 0.5
v 0 1 0.5
f 1 2 3
f 1 3 4
f 5 6 7
f 5 7 8
OBJ

# The same floor square and a vertical square through its middle (x = 0.5,
# y from 0.25 to 0.75, z from -1 to 1). Along x = 0.5 the floor triangles
# hold y in [0, 0.5] and [0.5, 1], the wall triangles meet z = 0 in y in
# [0.5, 0.75] and [0.25, 0.5]: all 4 floor-wall pairs meet (two of them
# touching at y = 0.5). A fifth triangle far away meets nothing.
cat >crossing.obj <<'OBJ'
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
v 0.5 0.25 -1
v 0.5 0.75 -1
v 0.5 0.75 1
v 0.5 0.25 1
v 5 5 5
v 6 5 5
v 5 6 5
f 1 2 3
f 1 3 4
f 5 6 7
f 5 7 8
f 9 10 11
OBJ

# --- help
run 0 intersections --help
grep -q -- '--list' out.txt || fail "'intersections --help' does not explain --list"
run 0 help intersections
grep -q 'exit status' out.txt || fail "'help intersections' gives no exit statuses"
run 0 --help
grep -q 'intersections' out.txt || fail "--help does not mention intersections"

# --- a clean mesh: 0 pairs, status 0
run 0 intersections clean.obj
grep -q '^0 intersecting triangle pairs$' out.txt || fail "clean mesh: '$(cat out.txt)'"
run 0 intersections --list clean.obj
[ "$(wc -l <out.txt | tr -d ' ')" -eq 1 ] || fail "--list on a clean mesh printed pairs"

# --- an intersecting mesh: status 1, and --list names the pairs
run 1 intersections crossing.obj
grep -q '^4 intersecting triangle pairs$' out.txt || fail "crossing mesh: '$(cat out.txt)'"
run 1 intersections crossing.obj --list
grep -q '^4 intersecting triangle pairs$' out.txt || fail "crossing mesh with --list: '$(cat out.txt)'"
[ "$(grep -c '^[0-9][0-9]* [0-9][0-9]*$' out.txt)" -eq 4 ] || fail "--list did not print 4 pairs"
# the floor triangles are 0 and 1, the wall 2 and 3 (assimp keeps face order)
for pair in "0 2" "0 3" "1 2" "1 3"; do
    grep -q "^$pair\$" out.txt || fail "--list lacks the pair $pair"
done

# --- bad input: status 2 with a message
run 2 intersections missing.obj
err_has 'missing.obj'
printf 'this is not a mesh\n' >bad.obj
run 2 intersections bad.obj
[ -s err.txt ] || fail "no message for an unreadable mesh"
run 2 intersections
err_has 'no mesh file'
run 2 intersections clean.obj crossing.obj
run 2 intersections --bogus clean.obj
err_has 'unknown option'

# --- a run whose cloths start through each other is refused before frame 1
# (a level sheet and one standing through its middle: 4 x 4 quads each),
# unless the scene accepts it: then a warning; apart, the same two sheets
# draw no warning.
scene() {
    cat >"$1" <<YAML
name: crossing
time: {fps: 1000, frames: 1}
effects: {self_collision: true}
self_collision: {thickness: 0.01, verify: true}
cloths:
  - grid: {size: [1, 1], resolution: [4, 4], center: [0, 1, 0]}
  - grid: {size: [1, 1], resolution: [4, 4], center: [0, $2, 0.1], rotation: [90, 0, 0]}
YAML
}
scene through.yaml 1
run 2 run through.yaml -o through -q
err_has 'through.yaml: the initial state intersects'
run 0 run through.yaml -o through -q --set check.allow_intersecting_start=true
err_has 'warning: through.yaml: the cloth starts intersecting \([0-9]+ intersecting triangle pairs'
scene apart.yaml 2
run 0 run apart.yaml -o apart -q
grep -q 'intersecting' err.txt && fail "sheets apart drew a warning"

echo "cli_intersections: all checks passed"
