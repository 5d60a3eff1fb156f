#!/bin/sh
# cli_scene_reference.sh CLOTHSIM_EXE SOURCE_DIR: docs/scene-reference.md's
# tables (and those of docs/input-check.md, the `check` section's) are the
# ones `clothsim help scene --markdown` prints from the table
# of keys (import/scene_keys.def), block by block between the
# <!-- scene-reference:begin SECTION --> and end markers; and
# `clothsim help scene` prints the reference, an unknown key names the
# nearest known one.
set -eu

NAME=cli_scene_reference
. "$2/tests/harness.sh"

# blocks FILE DIR: each marked block of FILE into DIR/SECTION.md (markers
# included), so that blocks compare whatever prose stands between them.
blocks() {
    mkdir -p "$2"
    awk -v dir="$2" '
        /^<!-- scene-reference:begin [a-z_]+ -->$/ { f = dir "/" $3 ".md"; n++ }
        f { print > f }
        /^<!-- scene-reference:end [a-z_]+ -->$/ { close(f); f = "" }
        END { if (f) { print "unterminated block " f > "/dev/stderr"; exit 1 } }
    ' "$1"
}

run 0 help scene --markdown
cp out.txt generated.md
blocks generated.md generated || fail "the generated reference has an unterminated block"
blocks "$2/docs/scene-reference.md" readme ||
    fail "docs/scene-reference.md has an unterminated scene-reference block"
blocks "$2/docs/input-check.md" readme ||
    fail "docs/input-check.md has an unterminated scene-reference block"
[ -n "$(ls generated)" ] || fail "help scene --markdown printed no block"
if ! diff -r -u readme generated >diff.txt; then
    cat diff.txt >&2
    fail "docs/scene-reference.md differs from 'clothsim help scene --markdown' \
(import/scene_keys.def); paste that command's blocks into docs/scene-reference.md and \
docs/input-check.md (scripts/update-scene-reference.py does)"
fi

# the text form names every section and key
run 0 help scene
grep -q '^time$' out.txt || fail "help scene lacks the time section"
grep -q '^  edge_flip_epsilon ' out.txt || fail "help scene lacks edge_flip_epsilon"
run 1 help scene --bogus
err_has 'usage: clothsim help scene'

# an unknown key names the nearest known one, with file and line
cat >typo.yaml <<'YAML'
cloths:
  - grid:
      resolutoin: [4, 4]
YAML
run 2 run typo.yaml --plan
err_has 'typo\.yaml:3: cloths\[0\]\.grid\.resolutoin: unknown key; did you mean resolution\?$'
echo "$NAME: ok"
