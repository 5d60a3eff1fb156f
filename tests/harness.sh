# harness.sh: the shared harness of the command-line tests, sourced by
# tests/cli_*.sh after setting NAME. Each test runs in its own temporary
# directory; out.txt and err.txt hold the last command's output.
EXE=$1
TMP=$(mktemp -d "${TMPDIR:-/tmp}/cs_$NAME.XXXXXX")
trap 'rm -rf "$TMP"' EXIT INT TERM
cd "$TMP"

fail() {
    echo "$NAME: FAIL: $*" >&2
    for f in out.txt err.txt; do
        if [ -s "$f" ]; then
            echo "--- $f" >&2
            cat "$f" >&2
        fi
    done
    exit 1
}

# run EXPECTED_STATUS ARGS...: runs clothsim, stdout to out.txt, stderr to err.txt.
run() {
    want=$1
    shift
    status=0
    "$EXE" "$@" >out.txt 2>err.txt || status=$?
    [ "$status" -eq "$want" ] || fail "clothsim $* exited $status, expected $want"
}

# mpi_run EXPECTED_STATUS NP ARGS...: clothsim under mpirun (MPIEXEC), the
# same way; MPI_ASAN_OPTIONS, when a test sets it, is ASAN_OPTIONS for it.
mpi_run() {
    want=$1
    np=$2
    shift 2
    status=0
    ASAN_OPTIONS=${MPI_ASAN_OPTIONS:-${ASAN_OPTIONS:-}} "${MPIEXEC:-mpirun}" --oversubscribe \
        -np "$np" "$EXE" "$@" >out.txt 2>err.txt || status=$?
    [ "$status" -eq "$want" ] || fail "mpirun -np $np clothsim $* exited $status, expected $want"
}

# err_has TEXT: stderr contains TEXT (a grep -E pattern).
err_has() {
    grep -E -q -- "$1" err.txt || fail "stderr lacks '$1'"
}
