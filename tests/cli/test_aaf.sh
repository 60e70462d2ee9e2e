#!/usr/bin/env bash
# CLI tests for axis-aligned filtering: --shadows aaf and --indirect aaf run and write their
# images, --stats has the sampling and filter passes, --aov has the beta, n(x) and unfiltered
# planes, and the AAF options' usage errors exit 2 without output.
# $1 is the drift binary.
set -u
drift="$1"
source "$(dirname "$0")/common.sh"
# --ism-vpls 8: the default indirect light (ism, 1024 VPLs) costs seconds a frame under the
# sanitizers; these checks are of behaviour, not of the image.
small=(--mode hybrid --width 32 --height 24 --threads 2 --spp 8 --quiet --ism-vpls 8)

expect 0 "$drift" render "${small[@]}" --shadows aaf --indirect aaf --out "$tmp/a.exr" \
    --stats "$tmp/a.json" --aov "$tmp/a-aov.exr"
[ -s "$tmp/a.exr" ] && [ -s "$tmp/a.png" ] || fail "aaf wrote no image"
python3 - "$tmp/a.json" <<'PY' || fail "aaf stats JSON incomplete"
import json, sys
s = json.load(open(sys.argv[1]))
assert s["techniques"]["shadows"] == "aaf" and s["techniques"]["indirect"] == "aaf", s
p = s["passes"]
assert p["aaf_sampling"]["rays"] > 0 and p["aaf_sampling"]["ms"] > 0.0, p
assert p["aaf_filter"]["ms"] >= 0.0, p
PY
for layer in light0.aaf.beta.Y light0.aaf.spp.Y light0.aaf.unfiltered.Y indirect.aaf.beta.Y \
             indirect.aaf.spp.Y indirect.aaf.unfiltered.R; do
    grep -aq "$layer" "$tmp/a-aov.exr" || fail "AOV file lacks $layer"
done

# The baseline and the options: plain Monte Carlo, a cap, two bounces.
expect 0 "$drift" render "${small[@]}" --shadows aaf --aaf-sampling uniform --aaf-filter off \
    --out "$tmp/mc.exr"
expect 0 "$drift" render "${small[@]}" --indirect aaf --aaf-max-spp 16 --max-depth 3 \
    --out "$tmp/b.exr"
[ -s "$tmp/b.exr" ] || fail "two-bounce aaf wrote no image"
expect 0 "$drift" render "${small[@]}" --shadows aaf --indirect aaf --aaf-sampler random \
    --out "$tmp/r.exr"
[ -s "$tmp/r.exr" ] || fail "random-sampled aaf wrote no image"
# The specular buffer: --reflections aaf, its planes in --aov.
expect 0 "$drift" render "${small[@]}" --reflections aaf --indirect aaf --out "$tmp/s.exr" \
    --aov "$tmp/s-aov.exr"
for layer in reflections.aaf.beta.Y reflections.aaf.spp.Y reflections.aaf.unfiltered.R; do
    grep -aq "$layer" "$tmp/s-aov.exr" || fail "AOV file lacks $layer"
done

# Usage errors.
expect 2 "$drift" render "${small[@]}" --aaf-sampling sometimes --out "$tmp/x.exr"
grep -q "adaptive or uniform" "$tmp/err" || fail "--aaf-sampling error does not list the choices"
expect 2 "$drift" render "${small[@]}" --aaf-filter maybe --out "$tmp/x.exr"
grep -q "on or off" "$tmp/err" || fail "--aaf-filter error does not list the choices"
expect 2 "$drift" render "${small[@]}" --aaf-sampler halton --out "$tmp/x.exr"
grep -q "sobol or random" "$tmp/err" || fail "--aaf-sampler error does not list the choices"
expect 2 "$drift" render "${small[@]}" --aaf-max-spp 0 --out "$tmp/x.exr"
expect 2 "$drift" render "${small[@]}" --shadows aaf --aaf-max-spp 4 --out "$tmp/x.exr"
grep -q "aaf max spp below spp" "$tmp/err" || fail "a cap under --spp is not explained"
expect 2 "$drift" render --aaf-filter off --out "$tmp/x.exr"
grep -q "needs --mode hybrid" "$tmp/err" || fail "aaf option in reference mode not explained"
[ -e "$tmp/x.exr" ] && fail "an output was written after a usage error"
expect 0 "$drift" render --help
grep -q -- "--aaf-max-spp" "$tmp/out" || fail "--help does not list --aaf-max-spp"
grep -q -- "--aaf-sampler" "$tmp/out" || fail "--help does not list --aaf-sampler"
grep -qE -- "isg( \(default\))?, blur or aaf" "$tmp/out" || fail "--help does not list --reflections aaf"

exit $((failures > 0))
