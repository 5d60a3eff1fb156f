#!/bin/sh
# cli_info.sh CLOTHSIM_EXE SOURCE_DIR: `clothsim info DIR` prints a row per
# frame of a run whose values are frames.jsonl's (time, max_speed, the
# verifier's pairs when recorded), counts the pairs itself when the records
# lack them (the same number), computes the energy of a falling sheet, and
# draws DIR/info.png.
set -eu

NAME=cli_info
. "$2/tests/harness.sh"

# Two sheets through each other (accepted), falling freely (no
# self-collision: with it the pairs stay jammed in place), the verifier
# counting their pairs at each frame's end. No vertex touches the other
# sheet: the frame files hold positions as 32-bit floats, the records count
# on the simulation's doubles, and a touching pair may differ between them.
cat >cross.yaml <<'YAML'
name: cross
time: {fps: 50, frames: 3}
effects: {self_collision: false}
self_collision: {thickness: 0.01, verify: true}
check: {allow_intersecting_start: true}
cloths:
  - name: level
    grid: {size: [1, 1], resolution: [4, 4], center: [0, 1, 0]}
    material: {density: 0.1}
  - name: standing
    grid: {size: [1, 1], resolution: [4, 4], center: [0, 1.1, 0.1], rotation: [90, 0, 0]}
    material: {density: 0.1}
YAML

run 0 info --help
grep -q -- '--no-verify' out.txt || fail "'info --help' does not explain --no-verify"
run 2 info nowhere
err_has 'nowhere has no summary.json'

run 0 run cross.yaml -o cross -q
run 0 info cross
grep -q '^run cross: scene cross.yaml, status ok, 4 frames written' out.txt ||
    fail "no header line"
[ -s cross/info.png ] || fail "no cross/info.png"
# the rows: frame time status pairs src kinetic potential max_speed fd_speed
awk '$1 ~ /^[0-9]+$/ && NF == 9' out.txt >rows.txt
[ "$(wc -l <rows.txt)" -eq 4 ] || fail "not 4 rows"
awk '$1 == 0 { exit !($3 == "initial" && $5 == "verifier" && $4 > 0) }' rows.txt ||
    fail "frame 0's pairs are not counted by the verifier"
# each record's time, max_speed and intersections, as the table prints them
sed 's/.*"frame":\([0-9]*\),"time":\([^,]*\),.*"max_speed":\([^,]*\),.*"intersections":\([^,]*\),.*/\1 \2 \3 \4/' \
    cross/frames.jsonl | awk '{ printf "%d %.6g %.6g %d\n", $1, $2, $3, $4 }' >records.txt
[ "$(wc -l <records.txt)" -eq 3 ] || fail "not 3 records in frames.jsonl"
awk '$1 > 0 { print $1, $2, $8, $4 }' rows.txt >table.txt
if ! cmp -s records.txt table.txt; then
    paste records.txt table.txt >&2
    fail "the table's time, max_speed and pairs differ from frames.jsonl's"
fi
awk '$1 > 0 { exit !($3 == "ok" && $5 == "rec") }' rows.txt || fail "frames 1.. are not ok, rec"

# a sheet falling freely: kinetic energy from the frames' positions is
# m (g t_mid)^2 / 2 (t_mid the middle of the frame), the potential -m g y,
# m = 0.1 kg/m^2 x 1 m^2 x 2 sheets
awk '$1 > 0 { t = $2 - 0.01; want = 0.5 * 0.2 * (9.8 * t) ^ 2;
              if (($6 - want) ^ 2 > (1e-3 * want) ^ 2) { print $1, $6, want; bad = 1 } }
     END { exit bad }' rows.txt || fail "kinetic energy is not m (g t)^2 / 2"
awk '$1 == 0 { exit !(($7 - 0.1 * 9.8 * (1 + 1.1)) ^ 2 < 1e-12) }' rows.txt ||
    fail "frame 0's potential is not the sheets' m g y = 2.058 J"

# without the records' pairs (verify off): the verifier counts the same
run 0 run cross.yaml -o plain -q --set self_collision.verify=false
run 0 info plain --no-plot
awk '$1 ~ /^[0-9]+$/ && NF == 9 { print $1, $4, $5 }' out.txt >plain.txt
awk '$1 > 0 { print $1, $4 }' rows.txt >want.txt
awk '$1 > 0 { print $1, $2 }' plain.txt >got.txt
cmp -s want.txt got.txt || fail "the verifier's pairs differ from the records'"
awk '$1 > 0 { exit !($3 == "verifier") }' plain.txt || fail "computed pairs not marked verifier"
[ ! -e plain/info.png ] || fail "--no-plot wrote info.png"
run 0 info plain --no-verify --no-plot
awk '$1 ~ /^[0-9]+$/ && NF == 9 { exit !($4 == "-" && $5 == "-") }' out.txt ||
    fail "--no-verify still counted pairs"

echo "$NAME: all checks passed"
