# Shared by the CLI test scripts: a temp dir, failure counting and an exit-status check.
# Source it after setting `drift` to the binary under test.
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
failures=0

fail() {
    echo "FAIL: $*" >&2
    failures=$((failures + 1))
}

# expect STATUS CMD...: runs CMD, stdout to $tmp/out, stderr to $tmp/err.
expect() {
    local want="$1"
    shift
    "$@" >"$tmp/out" 2>"$tmp/err"
    local got=$?
    if [ "$got" -ne "$want" ]; then
        fail "expected exit $want, got $got: $*"
        sed 's/^/  stderr: /' "$tmp/err" >&2
    fi
}
