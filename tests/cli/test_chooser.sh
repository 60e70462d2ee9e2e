#!/usr/bin/env bash
# drift render --mode hybrid --budget-ms (issue 40): on the built-in Cornell box and two corpus
# scenes at 32 x 32, the chooser (scenes/corpus/chooser.json) picks a row the renderer runs,
# whose measured ms in the model is within the budget (scaled to the model's size), and its
# image is within FLIP 0.3 of the path tracer at 128 spp (cached beside the binary; a black or
# wrong frame is at 0.5 and more). Bad --budget-ms and a missing model exit with errors.
# $1 is the drift binary.
set -u
drift="$1"
source "$(dirname "$0")/common.sh"
root="${DRIFT_SOURCE_DIR:-$(cd "$(dirname "$0")/../.." && pwd)}"
cache="$(dirname "$drift")/../test-cache"
mkdir -p "$cache"
[ -f "$root/scenes/corpus/chooser.json" ] || { fail "no scenes/corpus/chooser.json"; exit 1; }
if [ ! -d "$root/../shared/scenes" ]; then
    echo "SKIP: no ../shared/scenes"
    exit 77
fi
size=(--width 32 --height 32 --threads 2)
for scene in "" "$root/scenes/corpus/veach_mi.json" "$root/scenes/corpus/teapot_studio.json"; do
    name=$(basename "${scene:-builtin}" .json)
    ref="$cache/chooser-$name-32-128spp.exr"
    if [ ! -s "$ref" ]; then
        "$drift" render $scene "${size[@]}" --spp 128 --quiet --out "$ref" || fail "$name: reference"
    fi
    expect 0 "$drift" render $scene --mode hybrid --budget-ms 100 "${size[@]}" \
        --out "$tmp/$name.exr" --stats "$tmp/$name.json"
    line=$(grep -- "--budget-ms 100" "$tmp/err") || fail "$name: the choice is not said"
    python3 - "$line" <<'PY' || fail "$name: the pick is over its budget: $line"
import re, sys
m = re.search(r"\((\d+) ms at the model's .* at (\d+) ms: ([\d.]+) ms, FLIP", sys.argv[1])
assert m, sys.argv[1]
scaled, band, ms = float(m.group(1)), float(m.group(2)), float(m.group(3))
assert ms <= band <= max(scaled, band), (ms, band, scaled)
PY
    flip=$("$drift" diff "$ref" "$tmp/$name.exr" | awk '$1 == "flip" { print $2 }')
    echo "$name: FLIP $flip against 128 spp ($line)"
    python3 -c "import sys; sys.exit(0 if float('$flip') <= 0.3 else 1)" ||
        fail "$name: FLIP $flip over 0.3"
done
expect 2 "$drift" render --mode hybrid --budget-ms -5 "${size[@]}" --out "$tmp/x.exr"
expect 2 "$drift" render --budget-ms 100 "${size[@]}" --out "$tmp/x.exr"
expect 1 "$drift" render --mode hybrid --budget-ms 100 --chooser "$tmp/none.json" "${size[@]}" \
    --out "$tmp/x.exr"
exit $((failures > 0))
