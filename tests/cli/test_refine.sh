#!/usr/bin/env bash
# CLI tests for smart image refinement: `drift render --mode hybrid --refine sir` writes the
# refined image, its planes and its figures; refining every pixel reproduces the pure image;
# `drift refine fit` writes a lambda file that --refine sir reads back; `drift bench sir`
# runs on a tiny size; usage errors exit 2 and write nothing.
# $1 is the drift binary.
set -u
drift="$1"
source "$(dirname "$0")/common.sh"
small=(--mode hybrid --width 32 --height 24 --threads 2 --quiet --shadows pcss
       --reflections envmap --dof post --aperture 5 --shadow-map-size 64 --envmap-size 16)

# A refinement to the end: every error pixel refined, planes and stats written.
expect 0 "$drift" render "${small[@]}" --refine sir --budget 100 --refine-spp 2 \
    --out "$tmp/r.exr" --aov "$tmp/r-aov.exr" --stats "$tmp/r.json"
[ -s "$tmp/r.exr" ] && [ -s "$tmp/r.png" ] || fail "--refine sir wrote no image"
for layer in refined.R error.combined.Y refine.mask.Y refine.samples.Y error.reflection1.Y \
             error.reflection5.Y error.dof.Y error.shadow.Y error.leak.Y final.R N.X; do
    grep -aq "$layer" "$tmp/r-aov.exr" || fail "AOV file lacks $layer"
done
python3 - "$tmp/r.json" <<'PY' || fail "refine stats JSON incomplete or not refined"
import json, sys
s = json.load(open(sys.argv[1]))
assert s["refine"] == "sir" and s["width"] == 32 and s["height"] == 24, s
assert s["done"] is True and s["refined"] == s["requested"] == s["error_pixels"] > 0, s
assert s["samples"] == 2 * s["error_pixels"], s
assert s["iterations"] >= s["samples"] // 100, s
for k in ("metrics", "sort", "trace", "refine"):
    assert s["milliseconds"][k] >= 0.0, k
PY

# SIR's tracer has no indirect light: without --indirect a refined frame starts from none (no
# note that refined pixels lose it), though the hybrid frame's own default is ism.
tiny=(--mode hybrid --width 16 --height 12 --threads 2 --refine sir --budget 50)
expect 0 "$drift" render "${tiny[@]}" --out "$tmp/n.exr"
! grep -q "no indirect light" "$tmp/err" || fail "--refine sir did not start from --indirect none"
expect 0 "$drift" render "${tiny[@]}" --indirect ism --ism-vpls 8 --out "$tmp/n.exr"
grep -q "no indirect light" "$tmp/err" || fail "--refine sir --indirect ism: no note"

# An iteration limit stops early; the budget caps the samples of that iteration.
expect 0 "$drift" render "${small[@]}" --refine sir --budget 10 --refine-iterations 1 \
    --out "$tmp/one.exr" --stats "$tmp/one.json"
python3 -c "import json; s=json.load(open('$tmp/one.json')); assert s['iterations']==1 and s['samples']<=10 and not s['done'], s" \
    || fail "--refine-iterations 1 did not stop after one iteration"

# --refine-all with the whole image in one budget is the pure image; two runs with different
# budgets reach the same image bit for bit.
expect 0 "$drift" render "${small[@]}" --refine sir --refine-all --refine-spp 2 \
    --out "$tmp/all1.exr"
expect 0 "$drift" render "${small[@]}" --refine sir --refine-all --refine-spp 2 --budget 37 \
    --out "$tmp/all2.exr"
expect 0 "$drift" diff "$tmp/all1.exr" "$tmp/all2.exr" --json
python3 -c "import json,sys; d=json.load(open('$tmp/out')); sys.exit(0 if d['mse']==0 else 1)" \
    || fail "refining everything with two budgets gave different images"

# --refine-components changes only what a refined pixel traces: it is ignored with
# --refine-all (still the pure image, bit for bit).
expect 0 "$drift" render "${small[@]}" --refine sir --refine-all --refine-spp 2 \
    --refine-components --out "$tmp/all3.exr"
expect 0 "$drift" diff "$tmp/all1.exr" "$tmp/all3.exr" --json
python3 -c "import json,sys; d=json.load(open('$tmp/out')); sys.exit(0 if d['mse']==0 else 1)" \
    || fail "--refine-components with --refine-all did not give the pure image"

# Fit lambda on the built-in Cornell box, then refine with it.
expect 0 "$drift" refine fit --out "$tmp/lambda.json" --views 2 --width 24 --height 18 --spp 1 \
    --trials 50 --threads 2
python3 -c "import json; l=json.load(open('$tmp/lambda.json'))['lambda']; assert len(l)==8 and all(v>=0 for v in l.values())" \
    || fail "refine fit wrote no lambda file"
expect 0 "$drift" render "${small[@]}" --refine sir --lambda "$tmp/lambda.json" --out "$tmp/l.exr"

# The benchmark runs at a tiny size and prints JSON rows.
expect 0 "$drift" bench sir "$(dirname "$0")/../../scenes/cornell-box/cornell_box.json" \
    --sizes 24x18 --spp 1 --threads 2 --json
python3 -c "import json; d=json.load(open('$tmp/out')); r=d['rows'][0]; assert r['width']==24 and 'shadow' in r['quality'], d" \
    || fail "bench sir JSON incomplete"

# --views: one row per view and size, named; bad files are reported with file and line.
printf '{"views": [\n  {"name": "camera2"},\n  {"name": "up", "target": [278, 500, 0], "fov_y": 30, "aperture_radius": 0}\n]}\n' > "$tmp/views.json"
expect 0 "$drift" bench sir "$(dirname "$0")/../../scenes/cornell-box/cornell_box.json" \
    --sizes 16x12 --spp 1 --threads 2 --json --views "$tmp/views.json"
python3 -c "import json; d=json.load(open('$tmp/out')); assert [r['view'] for r in d['rows']]==['camera2','up'], d" \
    || fail "bench sir --views rows"
printf '{"views": [\n  {"name": "a"},\n  {"name": "b", "fov_y": "wide"}\n]}\n' > "$tmp/bad_views.json"
expect 2 "$drift" bench sir --views "$tmp/bad_views.json"
grep -q 'bad_views.json:3: error: views\[1\]\.fov_y must be a number' "$tmp/err" || fail "bad view not located"
printf '{"views": [\n  {"name": "a",}\n]}\n' > "$tmp/bad_views.json"
expect 2 "$drift" bench sir --views "$tmp/bad_views.json"
grep -q "bad_views.json:2: error: malformed JSON" "$tmp/err" || fail "views syntax error not located"

# Usage errors: exit 2, nothing written.
expect 2 "$drift" render --mode hybrid --refine bogus --out "$tmp/x.exr"
grep -q "expects 'sir'" "$tmp/err" || fail "--refine bogus not explained"
expect 2 "$drift" render --mode hybrid --budget 100 --out "$tmp/x.exr"
grep -q "needs --refine sir" "$tmp/err" || fail "--budget without --refine not explained"
expect 2 "$drift" render --refine sir --out "$tmp/x.exr"
grep -q "needs --mode hybrid" "$tmp/err" || fail "--refine in reference mode not explained"
expect 2 "$drift" render --mode hybrid --refine sir --budget 0 --out "$tmp/x.exr"
expect 2 "$drift" render --mode hybrid --refine sir --refine-iterations 2 --refine-time 1 \
    --out "$tmp/x.exr"
grep -q "not both" "$tmp/err" || fail "iterations and time together not explained"
expect 2 "$drift" render "${small[@]}" --refine sir --lambda "$tmp/missing.json" --out "$tmp/x.exr"
expect 2 "$drift" refine fit --views 2
grep -q "\-\-out" "$tmp/err" || fail "refine fit without --out not explained"
expect 2 "$drift" refine shuffle
expect 2 "$drift" bench sir --sizes 10by10
[ ! -e "$tmp/x.exr" ] && [ ! -e "$tmp/x.png" ] || fail "a usage error wrote an image"

exit $((failures > 0))
