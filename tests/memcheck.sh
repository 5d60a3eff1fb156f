#!/bin/sh
# memcheck.sh CLOTHSIM_EXE SOURCE_DIR: valgrind's memcheck on the scenes that
# run self-collision and body contact, on a build without sanitizers
# (valgrind cannot run AddressSanitizer's). It sees what ASan cannot: reads
# of memory never written (step C once read a history vector it had not
# set, and results depended on leftovers). Run by scripts/test.sh
# after the suite; it is kept to a few small scenes because valgrind is slow,
# and runs them two at a time.
set -eu

NAME=memcheck
. "$2/tests/harness.sh"
SCENES="$2/scenes"
export OMP_NUM_THREADS=1

# memcheck NAME ARGS...: clothsim under valgrind in the background (valgrind
# runs one thread, so two at a time fill a 2-core machine), its output in
# NAME.out and NAME.err; check NAME waits for it and fails on any error.
memcheck() {
    what=$1
    shift
    valgrind -q --error-exitcode=9 --leak-check=no "$EXE" "$@" >"$what.out" 2>"$what.err" &
    eval "pid_$what=\$!"
}
check() {
    what=$1
    status=0
    eval "wait \$pid_$what" || status=$?
    if [ "$status" -ne 0 ]; then
        cat "$what.err" >&2
        fail "$what: valgrind or clothsim exited $status"
    fi
    echo "$NAME: $what: no errors"
}

# step C finds a collision in frame 3
memcheck stack run "$SCENES/stack.yaml" -o stack --frames 3 -q
# repulsions and the verifier on a twisting strip
memcheck twist run "$SCENES/twist.yaml" -o twist --frames 4 -q \
    --set 'cloths.0.grid.resolution=[40,10]' --set self_collision.zone_iterations=2
check stack
python3 - stack/summary.json <<'PY' || fail "the stack had no collision to check"
import json, sys
assert sum(f.get("collisions", 0) for f in json.load(open(sys.argv[1]))["frames"]) > 0
PY
# body contact and friction, both methods
memcheck drape run "$SCENES/drape.yaml" -o drape --frames 8 -q \
    --set 'cloths.0.grid.resolution=[12,12]' --set 'cloths.0.grid.center=[0,0.8,0]'
check twist
memcheck projection run "$SCENES/drape.yaml" -o drape_p --frames 8 -q \
    --set 'cloths.0.grid.resolution=[12,12]' --set 'cloths.0.grid.center=[0,0.8,0]' \
    --set effects.friction=projection
check drape
check projection
python3 - drape/summary.json <<'PY' || fail "the drape never touched the ball"
import json, sys
assert sum(f["body_contacts"] for f in json.load(open(sys.argv[1]))["frames"]) > 0
PY
echo "$NAME: ok"
