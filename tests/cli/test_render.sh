#!/usr/bin/env bash
# CLI tests for `drift render`: outputs and stats on the built-in scene, usage errors, no
# output on failure, single-sample replay, and Ctrl-C writing what was rendered.
# $1 is the drift binary.
set -u
drift="$1"
source "$(dirname "$0")/common.sh"

# A tiny render of the built-in Cornell box writes EXR (with AOV layers), PNG and stats.
expect 0 "$drift" render --spp 2 --width 24 --height 24 --threads 2 --aov --checkpoint 0 \
    --out "$tmp/a.exr" --stats "$tmp/a.json"
[ -s "$tmp/a.exr" ] || fail "no EXR written"
[ -s "$tmp/a.png" ] || fail "no PNG written beside the EXR"
grep -q "wrote $tmp/a.exr" "$tmp/out" || fail "render does not say where the image went"
python3 - "$tmp/a.json" <<'PY' || fail "stats JSON incomplete"
import json, sys
s = json.load(open(sys.argv[1]))
assert s["spp"] == 2 and s["width"] == 24 and s["height"] == 24, s
assert s["rays"]["camera"] == 2 * 24 * 24, s["rays"]
assert s["rays"]["total"] >= s["rays"]["camera"] + s["rays"]["shadow"]
for phase in ("load", "accel", "render", "write", "total"):
    assert s["milliseconds"][phase] >= 0.0
assert s["nan_samples"] == 0
PY
for layer in albedo.R N.X Z; do
    grep -aq "$layer" "$tmp/a.exr" || fail "EXR lacks the $layer channel"
done

# The same seed gives the same image whatever the thread count (drift diff: zero error).
expect 0 "$drift" render --spp 2 --width 24 --height 24 --threads 1 --checkpoint 0 --quiet \
    --out "$tmp/b.exr"
expect 0 "$drift" diff "$tmp/a.exr" "$tmp/b.exr" --json
python3 -c "import json,sys; d=json.load(open('$tmp/out')); sys.exit(0 if d['mse']==0 else 1)" \
    || fail "1-thread and 2-thread renders differ"

# Replaying one sample is deterministic.
expect 0 "$drift" render --width 24 --height 24 --debug-sample 12,12,1
first=$(cat "$tmp/out")
expect 0 "$drift" render --width 24 --height 24 --debug-sample 12,12,1
[ "$first" = "$(cat "$tmp/out")" ] || fail "--debug-sample is not repeatable"

# Usage errors: exit 2 with a message, and nothing written.
expect 2 "$drift" render --spp zero --out "$tmp/c.exr"
expect 2 "$drift" render --spp 0 --out "$tmp/c.exr"
expect 2 "$drift" render --out "$tmp/c.png"
expect 2 "$drift" render --bogus
expect 2 "$drift" render --sp 4 --out "$tmp/c.exr"
grep -q "did you mean '--spp'" "$tmp/err" || fail "no 'did you mean' for --sp"
expect 2 "$drift" render --shadows pcff --out "$tmp/c.exr"
grep -q "did you mean 'pcf'" "$tmp/err" || fail "no 'did you mean' for a technique"
expect 2 "$drift" render --mode hybird --out "$tmp/c.exr"
grep -q "did you mean 'hybrid'" "$tmp/err" || fail "no 'did you mean' for a choice"
expect 2 "$drift" render --mode bogus --out "$tmp/c.exr"
[ -e "$tmp/c.exr" ] && fail "an output was written after a usage error"
expect 0 "$drift" render --help
grep -q -- "--max-depth" "$tmp/out" || fail "--help does not list --max-depth"

# A missing scene fails clearly, naming the file, and writes nothing.
expect 1 "$drift" render "$tmp/nope.json" --out "$tmp/d.exr"
grep -q "nope.json" "$tmp/err" || fail "missing scene not named in the error"
[ -e "$tmp/d.exr" ] && fail "an output was written for a missing scene"

# An unwritable output fails and leaves no temporary file behind.
expect 1 "$drift" render --spp 1 --width 8 --height 8 --quiet --out "$tmp/missing-dir/e.exr"
[ -z "$(ls "$tmp" | grep -v -E '^(a|b)\.(exr|png|json)$|^out$|^err$')" ] || fail "stray files: $(ls "$tmp")"

# Ctrl-C: the render stops, writes what it has and exits 130.
"$drift" render --spp 100000 --width 64 --height 64 --threads 1 --checkpoint 0 \
    --out "$tmp/int.exr" --stats "$tmp/int.json" >"$tmp/out" 2>"$tmp/err" &
pid=$!
# Once a pass is done (its progress line), not a fixed wait: at least 1 spp is in the image.
for _ in $(seq 100); do grep -q "spp (" "$tmp/err" 2>/dev/null && break; sleep 0.1; done
kill -INT "$pid"
wait "$pid"
status=$?
[ "$status" -eq 130 ] || fail "interrupted render exited $status, expected 130"
[ -s "$tmp/int.exr" ] || fail "interrupted render wrote no image"
grep -q "interrupted" "$tmp/err" || fail "interrupted render did not say so"
python3 -c "import json; s=json.load(open('$tmp/int.json')); assert 0 < s['spp'] < 100000, s" \
    || fail "interrupted stats do not show a partial spp"

# --denoise atrous|on writes the filtered image: smoother than the plain one of the same
# seed, closer to a converged render; a bad value is a usage error. 64 px: at 32 the a-trous
# image was as often a little further from the converged one as closer (FLIP 0.1591 against
# 0.1596 with one seed), at 64 closer by 0.005-0.011 for each of three seeds.
for d in none atrous on; do
    expect 0 "$drift" render --spp 2 --width 64 --height 64 --threads 2 --checkpoint 0 --quiet \
        --denoise "$d" --out "$tmp/dn-$d.exr" --stats "$tmp/dn-$d-stats.json"
done
# The filter's milliseconds are in --stats (a denoised frame costs render + denoise), and
# only when it ran.
for d in atrous on; do
    python3 - "$tmp/dn-$d-stats.json" "$tmp/dn-none-stats.json" <<'PY' || fail "--stats lacks --denoise $d's milliseconds"
import json, sys
filtered, plain = (json.load(open(p))["milliseconds"] for p in sys.argv[1:3])
assert 0 < filtered["denoise"] <= filtered["write"], filtered
assert "denoise" not in plain, plain
PY
done
expect 0 "$drift" render --spp 128 --width 64 --height 64 --threads 2 --checkpoint 0 --quiet \
    --out "$tmp/dn-ref.exr"
expect 0 "$drift" diff "$tmp/dn-ref.exr" "$tmp/dn-none.exr" --json
cp "$tmp/out" "$tmp/dn-none.json"
expect 0 "$drift" diff "$tmp/dn-ref.exr" "$tmp/dn-atrous.exr" --json
python3 - "$tmp/dn-none.json" "$tmp/out" <<'PY' || fail "--denoise atrous does not bring the image closer"
import json, sys
plain, filtered = (json.load(open(p)) for p in sys.argv[1:3])
assert filtered["flip"] < plain["flip"], (plain, filtered)
PY
# --denoise on: a finite image near the plain one (relative MSE < 0.25; its quality is
# measured at 320x240 by bench/experiments/bench-denoise.sh: at a few dozen pixels the filter's footprint spans the
# whole box, docs/denoiser.md).
expect 0 "$drift" diff "$tmp/dn-none.exr" "$tmp/dn-on.exr" --json
python3 - "$tmp/out" <<'PY' || fail "--denoise on's image is not finite or far from the plain one"
import json, sys
d = json.load(open(sys.argv[1]))
assert d["nonfinite"] == 0 and d["relmse"] < 0.25, d
PY
# --aov writes the feature denoiser's inputs as layers.
for layer in variance feature_albedo feature_normal feature_depth direct direct_variance indirect_variance; do
    grep -aq "$layer" "$tmp/a.exr" || fail "--aov lacks the $layer layer"
done
expect 2 "$drift" render --denoise oidn --out "$tmp/never.exr"
grep -q -- "--denoise" "$tmp/err" || fail "a bad --denoise value is not named"
expect 2 "$drift" render --mode hybrid --denoise atrous --out "$tmp/never.exr"
grep -q "filters the path tracer" "$tmp/err" || fail "--denoise in hybrid mode is not refused"
[ -e "$tmp/never.exr" ] && fail "a refused render wrote its image"

# Exposure: --exposure auto, --ev100 and --camera-exposure change the PNG only (the EXR stays
# linear and unscaled), say the stops they chose, and refuse each other and bad values.
expect 0 "$drift" render --spp 2 --width 16 --height 16 --threads 1 --checkpoint 0 --seed 3 \
    --out "$tmp/x0.exr"
expect 0 "$drift" render --spp 2 --width 16 --height 16 --threads 1 --checkpoint 0 --seed 3 \
    --exposure auto --tonemap filmic --out "$tmp/x1.exr"
grep -q "PNG exposure .* stops (auto)" "$tmp/err" || fail "--exposure auto reports its stops"
expect 0 "$drift" diff "$tmp/x0.exr" "$tmp/x1.exr" --json
python3 -c 'import json,sys; d=json.load(open(sys.argv[1])); assert d["mse"] == 0, d' "$tmp/out" \
    || fail "--exposure auto changed the EXR"
cmp -s "$tmp/x0.png" "$tmp/x1.png" && fail "--exposure auto --tonemap filmic left the PNG as is"
expect 0 "$drift" render --spp 1 --width 8 --height 8 --checkpoint 0 --camera-exposure 16,0.01,100 \
    --out "$tmp/x2.exr"
grep -q "PNG exposure .* stops (EV100)" "$tmp/err" || fail "--camera-exposure reports its stops"
expect 2 "$drift" render --exposure auto --ev100 9 --out "$tmp/never.exr"
grep -q "one of --exposure, --ev100 and --camera-exposure" "$tmp/err" || fail "two exposures refused"
expect 2 "$drift" render --exposure bright --out "$tmp/never.exr"
expect 2 "$drift" render --ev100 99 --out "$tmp/never.exr"
expect 2 "$drift" render --camera-exposure 16,0,100 --out "$tmp/never.exr"
expect 2 "$drift" render --tonemap aces --out "$tmp/never.exr"
grep -q "\-\-tonemap expects clamp, reinhard or filmic" "$tmp/err" || fail "--tonemap names its values"

# In an empty directory the default output folder out/ is made.
mkdir "$tmp/empty"
(cd "$tmp/empty" && "$drift" render --spp 1 --width 8 --height 8 --quiet --checkpoint 0 \
    >/dev/null) || fail "drift render in an empty directory failed"
[ -s "$tmp/empty/out/render.exr" ] && [ -s "$tmp/empty/out/render.png" ] ||
    fail "drift render in an empty directory wrote no out/render.exr"
# A folder the user names is not made (a typo would make one).
expect 1 "$drift" render --spp 1 --width 8 --height 8 --quiet --out "$tmp/typo-dir/f.exr"
[ -e "$tmp/typo-dir" ] && fail "a missing --out folder was made"

# --environment replaces the scene's environment (glTF files carry none): a camera that sees no
# geometry shows it exactly, a colour or an image's texel times --environment-strength, over
# the scene's own environment (5).
cat >"$tmp/env-scene.json" <<'JSON'
{ "version": 1,
  "camera": { "position": [0, 0, 0], "target": [0, 0, -1], "up": [0, 1, 0], "fov_y": 30,
              "width": 8, "height": 6 },
  "materials": { "m": { "type": "diffuse", "diffuse": 0.5 } },
  "meshes": [ { "path": "env-tri.obj", "material": "m" } ],
  "environment": { "color": [5, 5, 5] } }
JSON
printf 'v 0 0 5\nv 1 0 5\nv 0 1 5\nf 1 2 3\n' >"$tmp/env-tri.obj"
PYTHONPATH="$(dirname "$0")" python3 - "$tmp" <<'PY'
import sys
from make_exr import exr
t = sys.argv[1]
exr(t + "/env-map.exr", 16, 8, lambda x, y: (0.1, 0.2, 0.3))
exr(t + "/env-want-map.exr", 8, 6, lambda x, y: (0.3, 0.6, 0.9))
exr(t + "/env-want-rgb.exr", 8, 6, lambda x, y: (0.5, 1.0, 2.0))
PY
expect 0 "$drift" render "$tmp/env-scene.json" --spp 1 --quiet --checkpoint 0 \
    --environment 0.25,0.5,1 --environment-strength 2 --out "$tmp/env-rgb.exr"
expect 0 "$drift" diff "$tmp/env-want-rgb.exr" "$tmp/env-rgb.exr" --json
python3 -c 'import json,sys; d=json.load(open(sys.argv[1])); assert d["mse"] < 1e-12, d' "$tmp/out" \
    || fail "--environment R,G,B: the background is not the colour times the strength"
expect 0 "$drift" render "$tmp/env-scene.json" --spp 1 --quiet --checkpoint 0 \
    --environment "$tmp/env-map.exr" --environment-strength 3 --out "$tmp/env-map-out.exr"
expect 0 "$drift" diff "$tmp/env-want-map.exr" "$tmp/env-map-out.exr" --json
python3 -c 'import json,sys; d=json.load(open(sys.argv[1])); assert d["mse"] < 1e-10, d' "$tmp/out" \
    || fail "--environment FILE: the background is not the map times the strength"
expect 1 "$drift" render "$tmp/env-scene.json" --spp 1 --quiet --environment "$tmp/no-such.hdr" \
    --out "$tmp/never.exr"
grep -q "no-such.hdr" "$tmp/err" || fail "a missing --environment file is not named"
expect 1 "$drift" render "$tmp/env-scene.json" --spp 1 --quiet --environment -1,0,0 \
    --out "$tmp/never.exr"
expect 2 "$drift" render "$tmp/env-scene.json" --spp 1 --quiet --environment "$tmp/env-map.exr" \
    --out "$tmp/env-map.exr"
[ -e "$tmp/never.exr" ] && fail "a failed --environment wrote an image"
# A mesh file without lights gets a stand-in sun; --environment replaces it with its
# environment: a grey quad in a furnace of 0.5 is then darker than the furnace (with the sun
# still there it would be about twice as bright).
printf 'v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nf 1 2 3 4\n' >"$tmp/env-quad.obj"
PYTHONPATH="$(dirname "$0")" python3 - "$tmp" <<'PY'
import sys
from make_exr import exr
exr(sys.argv[1] + "/env-half.exr", 16, 16, lambda x, y: (0.5, 0.5, 0.5))
PY
expect 0 "$drift" render "$tmp/env-quad.obj" --spp 16 --width 16 --height 16 --quiet \
    --checkpoint 0 --environment 0.5 --out "$tmp/env-quad.exr"
expect 0 "$drift" diff "$tmp/env-half.exr" "$tmp/env-quad.exr" --mask "$tmp/env-half.exr" --json
python3 -c 'import json,sys; d=json.load(open(sys.argv[1])); assert d["luminance"] < 1.0, d' \
    "$tmp/out" || fail "--environment kept the stand-in sun of a file without lights"

if [ "$failures" -ne 0 ]; then
    echo "$failures render CLI check(s) failed"
    exit 1
fi
echo "render CLI: all checks passed"
