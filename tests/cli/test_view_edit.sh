#!/usr/bin/env bash
# Reflection editing in `drift view` under a virtual X server (Xvfb), scripted through --press:
# a constraint picked on the teapot, its green handle dragged onto the red wall, a region
# added and the edit file saved. Screenshots before and after differ, the saved file holds
# the constraint and the region (test_reflect_edit.c loads such a file back), and a bad
# --press edit event is a usage error.
# $1 is the drift binary.
set -u
drift="$1"
source "$(dirname "$0")/common.sh"
root=${DRIFT_SOURCE_DIR:-$(cd "$(dirname "$0")/../.." && pwd)}
scene="$root/scenes/edit-teapot/edit_teapot.json"
if ! command -v xvfb-run >/dev/null 2>&1; then
    echo "FAIL: xvfb-run not found; install the xvfb and xauth packages (bash scripts/install-deps.sh)" >&2
    exit 1
fi
# SDL, X11 and Mesa keep memory until exit (see test_view.sh): no leak checks here.
export ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0"
# --indirect none: the default ism costs seconds a frame under the sanitizers.
view=(view "$scene" --width 160 --height 120 --threads 2 --frames 1 --reflections sharp --indirect none)

expect 0 xvfb-run -a "$drift" "${view[@]}" --no-overlay --screenshot "$tmp/before.png"
# The teapot's body at (80, 78); the red left wall at (3, 70).
expect 0 xvfb-run -a "$drift" "${view[@]}" --no-overlay --reflection-edits "$tmp/v.edit.json" \
    --press pick@80:78,green@3:70,edit-region,edit-geodesic-region,save-edits --screenshot "$tmp/after.png"
[ -s "$tmp/v.edit.json" ] || fail "the edit file was not saved"
grep -q '"defaultobject"' "$tmp/v.edit.json" || fail "no constraint on the teapot in the saved file"
grep -q '"euclidean"' "$tmp/v.edit.json" || fail "no region in the saved file"
grep -q '"geodesic"' "$tmp/v.edit.json" || fail "no geodesic region in the saved file"
expect 0 "$drift" diff "$tmp/before.png" "$tmp/after.png" --json
python3 -c "import json,sys; d=json.load(open('$tmp/out')); sys.exit(0 if d['mse'] > 0 else 1)" \
    || fail "the edited view looks the same as the unedited one"
expect 2 "$drift" view --press pick@x:1
grep -q "pick@X:Y" "$tmp/err" || fail "a bad pick@ does not say what it expects"

if [ "$failures" -ne 0 ]; then
    echo "$failures failure(s)" >&2
    exit 1
fi
echo "view: a scripted edit placed, dragged and saved"
