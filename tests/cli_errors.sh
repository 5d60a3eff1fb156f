#!/bin/sh
# cli_errors.sh CLOTHSIM_EXE SOURCE_DIR: wrong command lines exit 1 with the
# usage, bad scenes exit 2 with a message that says where, unwritable output
# exits 4; none of them leaves output behind.
set -eu

NAME=cli_errors
. "$2/tests/harness.sh"


cat >tiny.yaml <<'EOF'
cloths: [{grid: {size: [1, 1], resolution: [4, 4], center: [0, 0.5, 0]}}]
bodies: [{shape: plane, friction: 0.3}]
time: {frames: 3}
EOF

# --- the command line: status 1 and the usage on stderr
run 1
err_has 'usage'
run 1 frobnicate
err_has "frobnicate"
err_has 'usage'
run 1 --frobnicate
err_has 'usage'
run 1 run
err_has 'no scene'
err_has 'usage'
run 1 run tiny.yaml --bogus
err_has '--bogus'
err_has 'usage'
run 1 run tiny.yaml -x
err_has '-x'
run 1 run tiny.yaml --format stl
err_has 'stl'
run 1 run tiny.yaml --frames many
err_has 'many'
run 1 run tiny.yaml --frames -2
run 1 run tiny.yaml --set novalue
err_has 'KEY=VALUE'
run 1 run tiny.yaml --output
run 1 run tiny.yaml -o ""
run 1 run tiny.yaml other.yaml
run 1 help frobnicate
[ ! -e out ] || fail "a usage error wrote output"

# --- a missing scene file: status 2, the message names the file
run 2 run missing.yaml
err_has '^clothsim: '
err_has 'missing\.yaml'

# --- a misspelt key: status 2, FILE:LINE: in the message
cat >bad.yaml <<'EOF'
cloths: [{grid: {size: [1, 1], resolution: [4, 4], center: [0, 0.5, 0]}}]
bodies: [{shape: plane, friction: 0.3}]
time: {frames: 3}
gravty: [0, -9.8, 0]
EOF
run 2 run bad.yaml
err_has '^clothsim: '
err_has 'bad\.yaml:[0-9]+:'
err_has 'gravty'

# --- a value of the wrong type, and a bad override
cat >badtype.yaml <<'EOF'
cloths: [{grid: {size: [1, 1], resolution: [4, 4], center: [0, 0.5, 0]}}]
time: {frames: lots}
EOF
run 2 run badtype.yaml
err_has 'badtype\.yaml:[0-9]+:'
run 2 run tiny.yaml --set time.fraems=2
err_has '--set'
run 2 run tiny.yaml --set time.frames=two
err_has '--set'
run 2 run tiny.yaml --plan --set time.frames=two
[ ! -e out ] || fail "an invalid scene wrote output"

# --- self-collision settings are checked like every other key
run 2 run tiny.yaml --set effects.self_collision=true --set self_collision.thickness=0
err_has 'self_collision.thickness'
run 2 run tiny.yaml --set self_collision.scheme=sometimes
err_has 'fixed, rewind'
[ ! -e out ] || fail "a refused scene wrote output"

# --- a list as a key is YAML but not a scene key (libcyaml said "Internal error")
cat >complex_key.yaml <<'EOF'
cloths: [{grid: {size: [1, 1], resolution: [4, 4]}}]
? [a, b]
: 3
EOF
run 2 run complex_key.yaml --plan
err_has '^clothsim: complex_key.yaml:2: a key must be a plain name \(got a list\)'
# --- a band of 1e308 voxels is the band's fault, not the voxel size's
run 2 run tiny.yaml --set 'bodies=[{shape: mesh, mesh: {file: '"$2"'/assets/stanford-bunny.obj}, band: 1e308}]' --plan
err_has 'bodies\[0\].band: must be in \[1, 1000\] \(got 1e308\)'

# --- output that cannot be written: status 4, the message names the path
: >not_a_dir
run 4 run tiny.yaml -q -o not_a_dir/sub
err_has 'not_a_dir/sub'

echo "cli_errors: all checks passed"
