#!/usr/bin/env bash
# drift render --mode hybrid --budget-ms (issue 40): on the built-in Cornell box and two corpus
# scenes at 32 x 32, the chooser (scenes/corpus/chooser.json) picks a row the renderer runs,
# whose cost-model prediction is within the budget, and its image is within FLIP 0.3 of the
# path tracer at 128 spp (cached beside the binary; a black or wrong frame is at 0.5 and
# more). With a hand-made model where the path tracer's row is the best, it picks and renders
# the path tracer (and says so), also when a hybrid row is predicted only slightly better
# (within the model's pt_margin); where the hybrid row is clearly better, that. Bad
# --budget-ms and a missing model exit with errors.
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
m = re.search(r"\(predicted (\d+) ms, FLIP", sys.argv[1])
assert m and float(m.group(1)) <= 100, sys.argv[1]
PY
    flip=$("$drift" diff "$ref" "$tmp/$name.exr" | awk '$1 == "flip" { print $2 }')
    echo "$name: FLIP $flip against 128 spp ($line)"
    python3 -c "import sys; sys.exit(0 if float('$flip') <= 0.3 else 1)" ||
        fail "$name: FLIP $flip over 0.3"
done
# A model of one fitted scene and two candidates, both predicted at 10 ms (alpha = ln 10 at
# the model's 32 x 32, no cost features): the lower predicted FLIP ratio wins, but a hybrid
# row only below pt_margin (0.9) x the path tracer's.
"$drift" render --features --quiet >"$tmp/features.json" || fail "--features"
model() { # $1: the hybrid row's FLIP ratio, $2: the path tracer's
    python3 - "$1" "$2" "$tmp/model.json" "$tmp/features.json" <<'PY'
import json, math, sys
feats = json.load(open(sys.argv[4]))
names = list(feats)
json.dump({"size": 32, "k": 1, "pt_margin": 0.9, "features": names, "cost_features": [],
           "beta": {"pt": [], "hybrid": []}, "safety": {"pt": 1.0, "hybrid": 1.0},
           "scale": [1.0] * len(names),
           "candidates": [
               {"key": "hybrid|hard + none", "group": "hybrid", "alpha": math.log(10.0),
                "kind": "hybrid", "row": "hard + none", "shadows": "hard", "indirect": "none"},
               {"key": "pt|2 spp", "group": "pt", "alpha": math.log(10.0), "kind": "pt",
                "row": "pt 2 spp", "spp": 2, "scale": 1, "denoise": "none"}],
           "scenes": [{"name": "box", "features": [feats[n] for n in names],
                       "flip": {"hybrid|hard + none": float(sys.argv[1]),
                                "pt|2 spp": float(sys.argv[2])}}]}, open(sys.argv[3], "w"))
PY
}
for case in "1.5 1.0 pt" "0.95 1.0 pt" "0.5 1.0 hybrid"; do
    set -- $case
    model "$1" "$2" || fail "model $case"
    expect 0 "$drift" render --mode hybrid --budget-ms 50 --chooser "$tmp/model.json" \
        "${size[@]}" --out "$tmp/m.exr" --stats "$tmp/m.json"
    if [ "$3" = pt ]; then
        grep -q "the path tracer is expected to win: pt 2 spp" "$tmp/err" ||
            fail "hybrid $1, pt $2: not the path tracer: $(cat "$tmp/err")"
        grep -q '"mode": *"reference"' "$tmp/m.json" || fail "hybrid $1, pt $2: not rendered by the path tracer"
    else
        grep -q "hybrid hard + none" "$tmp/err" || fail "hybrid $1, pt $2: not the hybrid row"
    fi
done
expect 2 "$drift" render --mode hybrid --budget-ms -5 "${size[@]}" --out "$tmp/x.exr"
expect 2 "$drift" render --budget-ms 100 "${size[@]}" --out "$tmp/x.exr"
expect 1 "$drift" render --mode hybrid --budget-ms 100 --chooser "$tmp/none.json" "${size[@]}" \
    --out "$tmp/x.exr"
exit $((failures > 0))
