#!/usr/bin/env bash
# CLI tests for image space gathering: `--shadows/--reflections/--dof isg` alone and together,
# the blur baselines, sample counts and sigma, the ISG planes in --aov and the isg pass in
# --stats, and usage errors (exit 2, nothing written). $1 is the drift binary.
set -u
drift="$1"
source "$(dirname "$0")/common.sh"
# --ism-vpls 8: the default indirect light (ism, 1024 VPLs) costs seconds a frame under the
# sanitizers; these checks are of behaviour, not of the image.
small=(--width 32 --height 24 --threads 2 --spp 2 --quiet --ism-vpls 8)

for spec in "--shadows isg" "--reflections isg" "--dof isg" "--shadows blur" "--reflections blur" \
            "--shadows isg --reflections isg --dof isg"; do
    name="$(echo "$spec" | tr -d ' -')"
    expect 0 "$drift" render --mode hybrid "${small[@]}" $spec --aperture 5 --out "$tmp/$name.exr"
    [ -s "$tmp/$name.exr" ] && [ -s "$tmp/$name.png" ] || fail "$spec wrote no image"
done

# Every sample count of the paper's table, and sigma.
for n in 9 25 49 81; do
    expect 0 "$drift" render --mode hybrid "${small[@]}" --shadows isg --isg-search "$n" \
        --isg-gather "$n" --isg-sigma 100 --isg-range plane --out "$tmp/n$n.exr"
done

# The second depth layer for depth of field, and its planes.
expect 0 "$drift" render --mode hybrid "${small[@]}" --dof isg --isg-layers 2 --aperture 5 \
    --out "$tmp/l2.exr" --aov "$tmp/l2-aov.exr"
grep -aq "isg.layer2.colour" "$tmp/l2-aov.exr" || fail "AOV file lacks isg.layer2.colour"

# Stats and planes.
expect 0 "$drift" render --mode hybrid "${small[@]}" --shadows isg --reflections isg --dof isg \
    --aperture 5 --out "$tmp/s.exr" --stats "$tmp/s.json" --aov "$tmp/s-aov.exr"
python3 - "$tmp/s.json" <<'PY' || fail "isg stats JSON incomplete"
import json, sys
s = json.load(open(sys.argv[1]))
assert s["techniques"]["shadows"] == "isg" and s["techniques"]["reflections"] == "isg", s
assert s["techniques"]["dof"] == "isg", s
assert s["passes"]["isg"]["ms"] > 0.0, s["passes"]
PY
for layer in light0.isg isg.reflection isg.dof light0.hard_shadow.R reflection.distance.Y; do
    grep -aq "$layer" "$tmp/s-aov.exr" || fail "AOV file lacks $layer"
done

# Usage errors.
expect 2 "$drift" render --mode hybrid --isg-search 10 --out "$tmp/x.exr"
grep -q "perfect square" "$tmp/err" || fail "--isg-search 10: the message does not say why"
expect 2 "$drift" render --mode hybrid --isg-gather 0 --out "$tmp/x.exr"
expect 2 "$drift" render --mode hybrid --isg-gather 2000 --out "$tmp/x.exr"
expect 2 "$drift" render --mode hybrid --isg-sigma -1 --out "$tmp/x.exr"
expect 2 "$drift" render --mode hybrid --blur-radius 0 --out "$tmp/x.exr"
expect 2 "$drift" render --mode hybrid --isg-layers 3 --out "$tmp/x.exr"
expect 2 "$drift" render --mode hybrid --isg-range near --out "$tmp/x.exr"
expect 2 "$drift" render --mode hybrid --dof blur --out "$tmp/x.exr"
grep -q "isg" "$tmp/err" || fail "unknown dof technique: the message does not list isg"
expect 2 "$drift" render --isg-search 9 --out "$tmp/x.exr"
grep -q "needs --mode hybrid" "$tmp/err" || fail "isg option in reference mode not explained"
[ -e "$tmp/x.exr" ] && fail "an output was written after a usage error"
expect 0 "$drift" render --help
grep -q -- "--isg-search" "$tmp/out" || fail "--help does not list --isg-search"

exit $((failures > 0))
