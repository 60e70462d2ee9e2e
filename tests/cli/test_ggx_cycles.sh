#!/usr/bin/env bash
# The GGX material against Blender Cycles (issue 41), two scenes written by Blender's glTF
# exporter (tests/data/ggx/export_ggx_scene.py) and rendered by Cycles 3.4 (Multiscatter GGX,
# 1024 spp) once into cached EXRs (tests/data/ggx/make_reference.sh). No Blender at test time.
#
# 1. Four gold metal spheres of roughness 0.05, 0.25, 0.5, 0.8, a glass sphere, a floor, an
#    emissive slab and a point light (ggx_scene.glb): drift at 64x48, 64 spp must agree within
#    FLIP 0.05 and 3% in mean luminance, the glass and the metals' reflections included (drift
#    0.042-0.044 at 64 spp, four seeds; docs/lab/2026-12-07-issue-41-s6.md); without the energy
#    compensation, or with the glass thin-walled, FLIP is 0.10-0.11. Per object, the rough
#    (0.8) sphere alone (its coverage mask mask_metal3.exr, `drift diff --mask`): FLIP 0.10 and
#    2% (drift 0.078-0.088 and +0.4..+0.9% at 64 spp, four seeds; with the multiple-scattering
#    lobe 2.5 alpha wide at every roughness 0.106-0.131 and +2.7..+4.4%, which this fails).
# 2. The textured scene without the spheres (textured/, --textured --no-spheres: a
#    metallic-roughness checker floor of gold roughness 0.3 and plastic roughness 0.8, a
#    normal-mapped wall), as exported (mip-mapped sampler): FLIP 0.06 and 3% at 64 spp (drift
#    0.050, 0.037 at 256, issue 41's 0.05; docs/lab/2026-12-07-issue-41-s5.md). With the Burley
#    base's roughness left at the roughnessFactor's 1 instead of the texture's 0.8, the plastic
#    squares were 2-5% brighter: 0.073 (0.065 at 256), which this check fails. When the path
#    tracer's ray cone widened at rough bounces it blurred the normal map and the checker in the
#    floor's reflection: 0.121. drift's own noise at 64 spp about 0.03. Without the spheres: with them the textured scene is 0.086 at 64 spp,
#    their sub-pixel highlights and caustics (the first scene has them).
# DRIFT_GGX_SPP overrides the spp.
# $1 is the drift binary.
set -u
drift="$1"
here="$(dirname "$0")"
src="$(cd "$here/../.." && pwd)"
source "$here/common.sh"
data="$src/tests/data/ggx"
spp=${DRIFT_GGX_SPP:-64}

# against_cycles NAME SCENE REFERENCE FLIP_BOUND: drift's render of SCENE against REFERENCE.
against_cycles() {
    expect 0 "$drift" render "$2" --spp "$spp" --width 64 --height 48 --threads 2 \
        --checkpoint 0 --quiet --out "$tmp/$1.exr"
    grep -qi "warn" "$tmp/err" && fail "$1: warnings: $(cat "$tmp/err")"
    expect 0 "$drift" diff "$3" "$tmp/$1.exr" --json
    cp "$tmp/out" "$tmp/$1.json"
    python3 - "$1" "$4" "$tmp/$1.json" "$src/bench/cycles/exr_mean.py" "$3" "$tmp/$1.exr" \
        <<'PY' || fail "drift and Cycles disagree on the $1 scene"
import json, subprocess, sys
name, bound = sys.argv[1], float(sys.argv[2])
d = json.load(open(sys.argv[3]))
lum = []
for f in sys.argv[5:]:
    out = subprocess.run([sys.executable, sys.argv[4], f], capture_output=True, text=True,
                         check=True).stdout.split()
    r, g, b = (float(x) for x in out[1:4])
    lum.append(0.2126 * r + 0.7152 * g + 0.0722 * b)
ratio = lum[1] / lum[0]
print("cli.ggx_cycles, %s: FLIP %.4f (<= %g), mean luminance drift/Cycles %.4f (within 3%%)"
      % (name, d["flip"], bound, ratio))
sys.exit(0 if d["flip"] <= bound and abs(ratio - 1.0) <= 0.03 else 1)
PY
}

against_cycles spheres "$data/ggx_scene.glb" "$data/cycles_64x48.exr" 0.05
expect 0 "$drift" diff "$data/cycles_64x48.exr" "$tmp/spheres.exr" --mask "$data/mask_metal3.exr" \
    --json
python3 - "$tmp/out" <<'PY' || fail "drift and Cycles disagree on the rough sphere"
import json, sys
d = json.load(open(sys.argv[1]))
print("cli.ggx_cycles, the rough sphere (%d pixels): FLIP %.4f (<= 0.1), luminance drift/Cycles "
      "%.4f (within 2%%)" % (d["mask_pixels"], d["flip"], d["luminance"]))
sys.exit(0 if d["flip"] <= 0.1 and abs(d["luminance"] - 1.0) <= 0.02 else 1)
PY

# The textured scene as Blender exported it (its sampler mip-mapped: drift filters by the ray
# cone, Cycles 3.4 reads texels unfiltered; the cone keeps the camera's spread through bounces).
against_cycles textured "$data/textured/ggx_scene.gltf" "$data/textured/cycles_64x48.exr" 0.06

if [ "$failures" -ne 0 ]; then
    echo "$failures failure(s)" >&2
    exit 1
fi
echo "cli.ggx_cycles: ok"
