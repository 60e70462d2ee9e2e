#!/usr/bin/env bash
# drift against Blender Cycles on a glTF written by Blender's own exporter: Blender builds
# issue 22's scene (tests/data/gltf/export_blender_scene.py) and exports it, then Cycles
# renders the .glb through Blender's importer (bench/cycles/gltf_cycles.py) and drift renders
# the same file. Prints ꟻLIP and the mean-luminance ratio, and says whether issue 22's targets
# (ꟻLIP <= 0.08 at 256 spp, luminance within 5%) are met; exits 1 only when a render fails.
# Skips, saying so, where Blender is absent (scripts/install-cycles.sh).
#   bench/cycles/run_gltf_compare.sh build/release/bin/drift [SPP] [EXPORT-ARGS...]
# EXPORT-ARGS go to the export script (--roughness 1: every material rough, the diffuse case);
# GLTF=FILE compares that file instead (tests/data/gltf/blender_scene.gltf, the hand-written
# stand-in); W, H set the size (96×72).
set -u
drift="$1"
src="$(cd "$(dirname "$0")/../.." && pwd)"
source "$src/tests/cli/common.sh"

if ! command -v blender >/dev/null 2>&1 || ! blender --version >/dev/null 2>&1; then
    echo "run_gltf_compare: skipped: Blender is not installed (scripts/install-cycles.sh)"
    exit 0
fi
w=${W:-96}
h=${H:-72}
spp=${2:-256}
shift $(($# < 2 ? $# : 2))
if [ -n "${GLTF:-}" ]; then
    gltf="$GLTF"
else
    timeout 300 blender -b --factory-startup -noaudio --python \
        "$src/tests/data/gltf/export_blender_scene.py" -- --out "$tmp/x" "$@" >"$tmp/export.log" 2>&1 ||
        { tail -20 "$tmp/export.log"; fail "Blender's export failed"; exit 1; }
    gltf="$tmp/x/blender_export.glb"
fi
timeout 600 blender -b --factory-startup -noaudio --python "$src/bench/cycles/gltf_cycles.py" -- \
    --gltf "$gltf" --spp $spp --width $w --height $h --threads 2 --out "$tmp/cycles.exr" \
    >"$tmp/blender.log" 2>&1 || { tail -20 "$tmp/blender.log"; fail "Cycles render failed"; }
expect 0 "$drift" render "$gltf" --spp $spp --width $w --height $h --threads 2 --checkpoint 0 \
    --quiet --out "$tmp/drift.exr"
expect 0 "$drift" diff "$tmp/cycles.exr" "$tmp/drift.exr" --json
cp "$tmp/out" "$tmp/diff.json"
[ -n "${KEEP:-}" ] && cp "$tmp/cycles.exr" "$tmp/drift.exr" "$KEEP"/
python3 - "$tmp/diff.json" "$src/bench/cycles/exr_mean.py" "$tmp/cycles.exr" "$tmp/drift.exr" <<'PY' || fail "reading the images"
import json, subprocess, sys
d = json.load(open(sys.argv[1]))
means = []
for f in sys.argv[3:]:
    out = subprocess.run([sys.executable, sys.argv[2], f], capture_output=True, text=True,
                         check=True).stdout.split()
    r, g, b = (float(x) for x in out[1:4])
    means.append(0.2126 * r + 0.7152 * g + 0.0722 * b)
ratio = means[1] / means[0]
print("run_gltf_compare: FLIP %.4f (target <= 0.08: %s), mean luminance drift/Cycles %.4f "
      "(target within 5%%: %s)" % (d["flip"], "met" if d["flip"] <= 0.08 else "NOT met", ratio,
                                   "met" if abs(ratio - 1) <= 0.05 else "NOT met"))
PY

if [ "$failures" -ne 0 ]; then
    echo "$failures failure(s)" >&2
    exit 1
fi
echo "run_gltf_compare: done"
