#!/bin/sh
# cli_check.sh CLOTHSIM_EXE SOURCE_DIR: `clothsim check SCENE` finds what is
# wrong with a scene's initial state (the broken scenes of
# tests/data/broken/), finds every intersecting pair the independent
# verifier finds in the run's frame 0, `run` refuses an intersecting start
# with exit status 2 naming the scene file (unless the scene accepts it),
# `check --fix` lifts cloth out of a body, and no scene of scenes/ or
# tests/data/scenes/ is refused.
set -eu

NAME=cli_check
. "$2/tests/harness.sh"
B="$2/tests/data/broken"

# --- help
run 0 check --help
grep -q -- '--fix' out.txt || fail "'check --help' does not explain --fix"
run 0 --help
grep -q '^  check SCENE' out.txt || fail "--help does not list check"
run 2 check
err_has 'no scene file'

# --- a cloth through itself: the 4 pairs of its floor and wall squares
run 1 check "$B/self_intersecting.yaml"
grep -q '^error: 4 intersecting triangle pairs within a cloth$' out.txt ||
    fail "self_intersecting: not 4 pairs within the cloth"
for pair in "0 and 2" "0 and 3" "1 and 2" "1 and 3"; do
    grep -q "^  cloth 'folded' triangles $pair, near (" out.txt ||
        fail "self_intersecting: the pair $pair is not listed with its position"
done

# check finds the pairs `clothsim intersections` finds in frame 0 of the run
# (the scene accepts the start; OBJ keeps both cloths in one file)
same_as_verifier() { # SCENE: check's pairs = the verifier's on frame_0000.obj
    run 1 check "$1"
    ours=$(sed -n 's/^error: \([0-9]*\) intersecting triangle pairs.*/\1/p' out.txt |
        awk '{ n += $1 } END { print n + 0 }')
    verifier=$(sed -n 's/^checked: intersections (verifier: \([0-9]*\) pairs).*/\1/p' out.txt)
    [ "$ours" = "$verifier" ] || fail "$1: listed $ours pairs, the verifier counted $verifier"
    run 0 run "$1" -o start -q --frames 0 --format obj --set check.allow_intersecting_start=true
    err_has 'warning: .*the cloth starts intersecting'
    run 1 intersections start/frames/frame_0000.obj
    theirs=$(sed -n 's/^\([0-9]*\) intersecting triangle pairs$/\1/p' out.txt)
    [ "$ours" = "$theirs" ] || fail "$1: check found $ours pairs, clothsim intersections $theirs"
    [ "$ours" -gt 0 ] || fail "$1: no pair found"
}
same_as_verifier "$B/self_intersecting.yaml"
same_as_verifier "$B/crossing_cloths.yaml"
run 1 check "$B/crossing_cloths.yaml"
grep -q "^  cloth 'level' triangle 16 and cloth 'standing' triangle 8, near (" out.txt ||
    fail "crossing_cloths: the first pair is not named by cloth and triangle"
grep -q '^error: 40 intersecting triangle pairs between different cloths$' out.txt ||
    fail "crossing_cloths: not 40 pairs between cloths"
# the pairs themselves, for one cloth (its triangle indices are the file's)
run 1 check "$B/self_intersecting.yaml"
sed -n "s/^  cloth 'folded' triangles \([0-9]*\) and \([0-9]*\),.*/\1 \2/p" out.txt >ours.txt
run 0 run "$B/self_intersecting.yaml" -o start1 -q --frames 0 --format obj \
    --set check.allow_intersecting_start=true
run 1 intersections start1/frames/frame_0000.obj --list
grep '^[0-9]* [0-9]*$' out.txt >theirs.txt
[ -s ours.txt ] || fail "self_intersecting: no pair listed"
cmp -s ours.txt theirs.txt || fail "self_intersecting: check's pairs differ from --list's"

# --- run refuses an intersecting start: exit 2, the scene file, the list
for scene in self_intersecting crossing_cloths through_sphere through_box; do
    run 2 run "$B/$scene.yaml" -o "refused_$scene" -q
    err_has "$scene\\.yaml: the initial state intersects \\([0-9]+ findings?\\); refused"
    err_has "allow_intersecting_start"
    [ ! -e "refused_$scene/frames/frame_0000.ply" ] || fail "$scene: refused, yet frame 0 written"
done
run 2 run "$B/through_sphere.yaml" -o refused -q
err_has "^clothsim: error: 21 cloth vertices inside a body$"
err_has "^  cloth 'sheet' vertex 60 at \\(0, 0.5, 0\\): 0.25 m inside body 'ball'$"
run 1 check "$B/through_box.yaml"
grep -q "^error: 9 cloth vertices inside a body$" out.txt || fail "through_box: not 9 inside"
grep -q "^warning: 9 cloth edges through a body with both ends outside it$" out.txt ||
    fail "through_box: the edges across the slat are not found"
grep -q "^  cloth 'sheet' edge 2-3: 0.025 m inside body 'slat'" out.txt ||
    fail "through_box: edge 2-3 not named"

# --- warnings: not refused
run 0 check "$B/degenerate.yaml"
grep -q "^warning: 1 degenerate triangles" out.txt || fail "degenerate: not found"
grep -q "^  cloth 'bad' triangle 1 (vertices 0 1 3) at (1, 1, 0): area 0 m^2$" out.txt ||
    fail "degenerate: triangle 1 not named"
grep -q "^warning: 1 non-manifold edges" out.txt || fail "non-manifold edge not found"
grep -q "^  cloth 'bad' edge 0-1 at (0.5, 1, 0): in 3 triangles$" out.txt ||
    fail "non-manifold: edge 0-1 not named"
run 0 check "$B/too_close.yaml"
grep -q "^warning: 25 cloth vertices outside a body but closer than the threshold" out.txt ||
    fail "too_close: the lower sheet's 25 vertices 5 mm above the ground not found"
grep -q "^warning: [0-9]* vertex-triangle pairs of cloth closer than the thickness (0.01 m)$" \
    out.txt || fail "too_close: the sheets 5 mm apart not found"
grep -q "^  cloth 'upper' vertex 0 at (-0.5, 0.01, -0.5): 0.005 m from cloth 'lower' triangle 0$" \
    out.txt || fail "too_close: a close pair not named"
run 0 run "$B/too_close.yaml" -o close --frames 0
err_has "warning: .*too_close\\.yaml: the initial state has .*closer than the thickness"
run 0 run "$B/too_close.yaml" -o close_quiet --frames 0 -q
[ ! -s err.txt ] || fail "--quiet printed the warnings"

# --- a selection that selects nothing: the scene's error, file and line
run 2 check "$B/script_selects_nothing.yaml"
err_has 'script_selects_nothing\.yaml:8: cloths\[0\]\.pins\[0\]\.box: selects no vertex'
run 2 run "$B/script_selects_nothing.yaml" -o nothing -q
err_has 'script_selects_nothing\.yaml:8: .*selects no vertex'

# --- --fix: the sheet 1 cm into the top of the ball is lifted out
run 2 check "$B/through_sphere.yaml" --fix
err_has '--fix and -o DIR go together'
run 0 check "$B/through_sphere.yaml" --set 'bodies.0.position=[0,0.26,0]' --fix -o fixed
grep -q '^error: 1 cloth vertices inside a body$' out.txt || fail "--fix: not 1 vertex inside"
grep -q '^--fix: moved 1 vertices out of bodies, at most 0.02 m$' out.txt ||
    fail "--fix: not the one vertex lifted by 2 cm (1 cm in, to 1 cm out)"
grep -q '^after --fix: 0 errors left$' out.txt || fail "--fix left errors"
[ -s fixed/sheet.ply ] || fail "--fix wrote no fixed/sheet.ply"
grep -q 'mesh: {file: ".*/fixed/sheet.ply"}' fixed/cloths.yaml || fail "no snippet"
cat >refixed.yaml <<'YAML'
name: refixed
cloths:
  - name: sheet
    mesh: {file: fixed/sheet.ply}
bodies:
  - {name: ball, shape: sphere, radius: 0.25, position: [0, 0.26, 0]}
YAML
run 0 check refixed.yaml
grep -q 'inside a body' out.txt && fail "the fixed sheet is still inside the ball"
grep -q '^refixed.yaml: 1 cloth, 121 vertices, 200 triangles' out.txt ||
    fail "the fixed sheet did not keep its vertices and triangles"
# deep through the ball, lifting folds the sheet: said, and exit 1
run 1 check "$B/through_sphere.yaml" --fix -o folded
grep -q '^after --fix: the moved vertices made [0-9]* more intersecting' out.txt ||
    fail "--fix did not say it folded the sheet"

# --- no scene of the repository is refused
for scene in "$2"/scenes/*.yaml "$2"/scenes/*/*.yaml "$2"/tests/data/scenes/*.yaml; do
    run 0 check "$scene"
    grep -q "^result: no error" out.txt || fail "$scene: $(grep '^result' out.txt)"
done

echo "$NAME: all checks passed"
