#!/usr/bin/env bash
# CLI tests for `drift render --mode hybrid`: every technique of every effect runs and writes
# its image, --stats has every pass, --aov has the planes, all-reference equals the path
# tracer's image through pixel centres, and usage errors exit 2 without output.
# $1 is the drift binary.
set -u
drift="$1"
source "$(dirname "$0")/common.sh"
# --ism-vpls 8: the default indirect light (ism, 1024 VPLs) costs seconds a frame at any size
# under the sanitizers; these checks are of behaviour, not of the image's quality.
small=(--width 32 --height 24 --threads 2 --spp 2 --quiet --ism-vpls 8)

# Each technique of each effect, on the built-in Cornell box.
for spec in "shadows hard" "shadows pcf" "shadows pcss" "shadows reference" \
            "reflections none" "reflections envmap" "reflections sharp" "reflections reference" \
            "dof none" "dof post" "dof reference" \
            "indirect none" "indirect ambient" "indirect reference"; do
    set -- $spec
    expect 0 "$drift" render --mode hybrid "${small[@]}" --"$1" "$2" --aperture 5 \
        --shadow-map-size 64 --envmap-size 16 --out "$tmp/$1-$2.exr"
    [ -s "$tmp/$1-$2.exr" ] && [ -s "$tmp/$1-$2.png" ] || fail "--$1 $2 wrote no image"
done

# Stats: milliseconds and rays for every pass, the techniques by name.
expect 0 "$drift" render --mode hybrid "${small[@]}" --reflections sharp --dof post \
    --out "$tmp/s.exr" --stats "$tmp/s.json" --aov "$tmp/s-aov.exr"
python3 - "$tmp/s.json" <<'PY' || fail "hybrid stats JSON incomplete"
import json, sys
s = json.load(open(sys.argv[1]))
assert s["mode"] == "hybrid" and s["width"] == 32 and s["height"] == 24, s
# The chosen ones, and every other effect at the CLI's default (drift_hybrid_params_recommended:
# isg shadows and reflections, post dof, ism indirect light, max depth 8; issue 40).
t = s["techniques"]
assert (t["shadows"], t["reflections"], t["dof"], t["indirect"]) == ("isg", "sharp", "post", "ism"), t
assert s["max_depth"] == 8 and s["aa"] == 1, s
assert t.get("occlusion") == "none" and t.get("glare") == "none", t
assert set(s["effect_ms"]) == set(t) and all(v >= 0 for v in s["effect_ms"].values()), s["effect_ms"]
passes = s["passes"]
for name in ("primary", "unshadowed", "hard_shadows", "shadow_maps", "shadow_filter",
             "reflections", "envmap", "reference", "compose", "dof"):
    assert passes[name]["ms"] >= 0.0, name
assert passes["primary"]["rays"] == 32 * 24
assert passes["hard_shadows"]["rays"] > 0
assert s["rays"] == sum(p["rays"] for p in passes.values())
PY
for layer in final.R N.X albedo.R gloss.R material_id.Y motion.Y light0.hard_shadow.R \
             light0.unshadowed.R reflection.distance.Y coc.Y; do
    grep -aq "$layer" "$tmp/s-aov.exr" || fail "AOV file lacks $layer"
done

# All-reference at depth 2 is the path tracer's depth-2 image: compared with drift diff it
# is not the same estimator (the path tracer jitters within pixels), so only check it runs
# and is finite here; the exact equality is tested in unit.hybrid.
expect 0 "$drift" render --mode hybrid "${small[@]}" --shadows reference --reflections reference \
    --indirect reference --max-depth 2 --out "$tmp/ref.exr"
# Against itself the MSE is 0 only where every value is finite (NaN or inf give null).
expect 0 "$drift" diff "$tmp/ref.exr" "$tmp/ref.exr" --json
python3 -c "import json,sys; d=json.load(open('$tmp/out')); sys.exit(0 if d['mse']==0 else 1)" \
    || fail "all-reference image is not finite"

# Anti-aliasing passes: --aa N renders the frame N times (N G-buffers), --aa 0 is a usage error.
expect 0 "$drift" render --mode hybrid "${small[@]}" --aa 4 --out "$tmp/aa.exr" --stats "$tmp/aa.json"
python3 - "$tmp/aa.json" <<'PY' || fail "--aa 4: the stats do not count 4 passes"
import json, sys
s = json.load(open(sys.argv[1]))
assert s["aa"] == 4 and s["passes"]["primary"]["rays"] == 4 * 32 * 24, s
PY
expect 2 "$drift" render --mode hybrid --aa 0 --out "$tmp/x.exr"

# Usage errors: unknown technique names, hybrid options in reference mode, bad values.
expect 2 "$drift" render --mode hybrid --shadows soft --out "$tmp/x.exr"
grep -q "pcss" "$tmp/err" || fail "unknown technique: the message does not list the choices"
expect 2 "$drift" render --shadows pcf --out "$tmp/x.exr"
grep -q "needs --mode hybrid" "$tmp/err" || fail "hybrid option in reference mode not explained"
expect 2 "$drift" render --mode hybrid --probe 1,2 --out "$tmp/x.exr"
expect 2 "$drift" render --mode hybrid --pcf-kernel 0 --out "$tmp/x.exr"
expect 2 "$drift" render --aov "$tmp/x-aov.exr" --out "$tmp/x.exr"
# The environment's rays at one pixel in 2 x 2 (the default) give way to --env-interleave on;
# asked for together they are refused, by name.
expect 2 "$drift" render --mode hybrid "${small[@]}" --env-scale 2 --env-interleave on \
    --out "$tmp/x.exr"
grep -q "environment scale 2 with interleaving" "$tmp/err" || fail "--env-scale 2 with interleaving not explained"
expect 2 "$drift" render --mode hybrid --env-filter 11 --out "$tmp/x.exr"
[ -e "$tmp/x.exr" ] && fail "an output was written after a usage error"
expect 0 "$drift" render --mode hybrid "${small[@]}" --env-interleave on --out "$tmp/il.exr"
expect 0 "$drift" render --help
grep -q -- "--reflections" "$tmp/out" || fail "--help does not list --reflections"

# --frames N renders the one view N times: the same image (the frame is deterministic), the
# last frame's stats with the first one's milliseconds beside them.
expect 0 "$drift" render --mode hybrid "${small[@]}" --indirect ism --ism-vpls 8 --out "$tmp/f1.exr"
expect 0 "$drift" render --mode hybrid "${small[@]}" --indirect ism --ism-vpls 8 --frames 3 \
    --out "$tmp/f3.exr" --stats "$tmp/f3.json"
cmp -s "$tmp/f1.exr" "$tmp/f3.exr" || fail "--frames 3 wrote another image than one frame"
python3 -c "import json,sys; d=json.load(open(sys.argv[1])); m=d['milliseconds']
assert d['frames'] == 3 and m['first_frame'] > 0 and m['frame'] > 0, d" "$tmp/f3.json" \
    || fail "--frames stats"
expect 2 "$drift" render --mode hybrid "${small[@]}" --frames 0 --out "$tmp/f0.exr"

# --ism-later-paths: more of the paths go on past their first VPL, so more VPLs (--verbose logs
# each ISM render's count); a count whose maps would pass the scene-point limit is refused,
# naming the limit, and writes nothing.
for later in 2 8; do
    expect 0 "$drift" render --mode hybrid "${small[@]}" --indirect ism --ism-vpls 8 \
        --ism-later-paths "$later" --verbose --out "$tmp/later$later.exr"
    grep -o "ism: [0-9]* VPLs" "$tmp/err" | head -1 | tr -dc 0-9 >"$tmp/later$later.count"
done
[ "$(cat "$tmp/later8.count")" -gt "$(cat "$tmp/later2.count")" ] 2>/dev/null ||
    fail "--ism-later-paths 8 left no more VPLs than 2 ($(cat "$tmp/later8.count") vs $(cat "$tmp/later2.count"))"
expect 1 "$drift" render --mode hybrid "${small[@]}" --indirect ism --ism-vpls 65536 \
    --ism-later-paths 65536 --out "$tmp/too-many.exr"
grep -q "exceed 2^28 scene points" "$tmp/err" || fail "--ism-later-paths over the limit not explained"
[ ! -e "$tmp/too-many.exr" ] || fail "a refused ISM render wrote an image"

# Micro-rendering (docs/micro.md): both rows, with their planes, at the three densities; bad
# values of its options exit 2 naming the option.
for density in 1 1/4 1/16; do
    expect 0 "$drift" render --mode hybrid "${small[@]}" --indirect micro --reflections micro \
        --micro-points 1024 --micro-size 8 --micro-density "$density" --out "$tmp/micro.exr" \
        --aov "$tmp/micro-aov.exr"
    [ -s "$tmp/micro.exr" ] || fail "--indirect micro --micro-density $density wrote no image"
done
for layer in micro.incident.R micro.gathers.Y micro.glossy_incident.R; do
    grep -aq "$layer" "$tmp/micro-aov.exr" || fail "micro AOV file lacks $layer"
done
expect 2 "$drift" render --mode hybrid --indirect micro --micro-density 1/3 --out "$tmp/x.exr"
grep -q -- "--micro-density expects 1, 1/4 or 1/16, got '1/3'" "$tmp/err" \
    || fail "bad --micro-density not named"
expect 2 "$drift" render --mode hybrid --indirect micro --micro-size 64 --out "$tmp/x.exr"
grep -q -- "--micro-size" "$tmp/err" || fail "bad --micro-size not named"
expect 2 "$drift" render --mode hybrid --indirect micro --micro-points 0 --out "$tmp/x.exr"
[ -e "$tmp/x.exr" ] && fail "an output was written after a micro usage error"
# More bounces at the points (radiosity, photons), with reflections micro and --max-depth 3;
# direct light with 2 bounces, 0 bounces and an unknown lighting exit 2 naming the option.
for lighting in radiosity photons; do
    expect 0 "$drift" render --mode hybrid "${small[@]}" --indirect micro --reflections micro \
        --micro-points 512 --micro-size 4 --micro-bounces 2 --micro-lighting "$lighting" \
        --max-depth 3 --out "$tmp/micro-b2.exr"
    [ -s "$tmp/micro-b2.exr" ] || fail "--micro-lighting $lighting wrote no image"
    grep -q "micro:" "$tmp/err" && fail "--micro-bounces 2 --max-depth 3 warned: $(cat "$tmp/err")"
done
expect 2 "$drift" render --mode hybrid --indirect micro --micro-lighting direct --micro-bounces 2 \
    --out "$tmp/x.exr"
grep -q -- "--micro-lighting direct is one bounce" "$tmp/err" || fail "direct + 2 bounces not named"
expect 2 "$drift" render --mode hybrid --indirect micro --micro-bounces 0 --out "$tmp/x.exr"
grep -q -- "--micro-bounces" "$tmp/err" || fail "bad --micro-bounces not named"
expect 2 "$drift" render --mode hybrid --indirect micro --micro-lighting vpl --out "$tmp/x.exr"
grep -q -- "--micro-lighting" "$tmp/err" || fail "bad --micro-lighting not named"

exit $((failures > 0))
