#!/usr/bin/env bash
# The clear coat (KHR_materials_clearcoat) against Blender Cycles (issue 41): Blender's glTF
# export of four spheres (a red diffuse base bare, under a coat of roughness 0.05, under one of
# roughness 0.3, and a gold metal of roughness 0.5 under a coat of 0.05), a floor, an emissive
# slab and a point light (tests/data/clearcoat/export_clearcoat_scene.py), rendered by Cycles
# 3.4 (Multiscatter GGX, 1024 spp) once into tests/data/clearcoat/cycles_64x48.exr
# (tests/data/clearcoat/make_reference.sh). glTF files get the Principled form of the coat
# (docs/decisions/0411-gltf-clearcoat.md). drift renders the cached .glb at 64x48, 64 spp:
# FLIP <= 0.045 and mean luminance within 3% (measured 0.038 and -0.2%), the two coated red
# spheres' quarter of the sphere band within 2.5% of Cycles' (measured -0.9%, -1.5%) and the
# coated metal's within 4% (+2.8%). The glTF specification's layered form (JSON `ggx`'s)
# measures FLIP 0.050 here (0.043 at 256 spp: its coat highlights are 4x Cycles'); with the coats
# dropped the coated spheres are -2.3% and -3.4% at 256 spp
# (docs/lab/2026-12-07-issue-41-s4b.md). No Blender at test time. DRIFT_CLEARCOAT_SPP
# overrides the spp.
# ctest-labels: quality
# $1 is the drift binary.
set -u
drift="$1"
here="$(dirname "$0")"
src="$(cd "$here/../.." && pwd)"
source "$here/common.sh"
data="$src/tests/data/clearcoat"
spp=${DRIFT_CLEARCOAT_SPP:-64}

expect 0 "$drift" render "$data/clearcoat_scene.glb" --spp "$spp" --width 64 --height 48 \
    --threads 2 --checkpoint 0 --quiet --out "$tmp/drift.exr"
grep -qi "warn" "$tmp/err" && fail "warnings: $(cat "$tmp/err")"
expect 0 "$drift" diff "$data/cycles_64x48.exr" "$tmp/drift.exr" --json
cp "$tmp/out" "$tmp/diff.json"
python3 "$data/sphere_means.py" "$data/cycles_64x48.exr" "$tmp/drift.exr" >"$tmp/spheres" ||
    fail "sphere_means.py failed"
python3 - "$tmp/diff.json" "$src/bench/cycles/exr_mean.py" "$tmp/spheres" \
    "$data/cycles_64x48.exr" "$tmp/drift.exr" <<'PY' || fail "drift and Cycles disagree on the clear coats"
import json, subprocess, sys
d = json.load(open(sys.argv[1]))
lum = []
for f in sys.argv[4:]:
    out = subprocess.run([sys.executable, sys.argv[2], f], capture_output=True, text=True,
                         check=True).stdout.split()
    r, g, b = (float(x) for x in out[1:4])
    lum.append(0.2126 * r + 0.7152 * g + 0.0722 * b)
ratio = lum[1] / lum[0]
q = [float(x) for x in open(sys.argv[3]).read().split("ratio")[1].split()]
print("cli.clearcoat_cycles: FLIP %.4f (<= 0.045), mean luminance drift/Cycles %.4f (within 3%%), "
      "spheres %s (coated red within 2.5%%, coated metal within 4%%)"
      % (d["flip"], ratio, " ".join("%.3f" % x for x in q)))
ok = (d["flip"] <= 0.045 and abs(ratio - 1.0) <= 0.03 and abs(q[1] - 1.0) <= 0.025
      and abs(q[2] - 1.0) <= 0.025 and abs(q[3] - 1.0) <= 0.04)
sys.exit(0 if ok else 1)
PY

if [ "$failures" -ne 0 ]; then
    echo "$failures failure(s)" >&2
    exit 1
fi
echo "cli.clearcoat_cycles: ok"
