#!/usr/bin/env bash
# The path tracer with GGX materials against the same scene with Phong materials (issue 41's
# speed check): the glossy Cornell box floor and blocks, one thread, runs interleaved.
# usage: scripts/bench_ggx.sh [path/to/drift] [runs]
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
drift="${1:-$root/build/release/bin/drift}"
runs="${2:-3}"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
scene() { # $1 = material JSON of the floor
  cat > "$tmp/$2.json" <<JSON
{ "version": 1,
  "camera": { "position": [278, 273, -800], "target": [278, 273, 0], "up": [0, 1, 0],
              "fov_y": 39.3077, "width": 96, "height": 96 },
  "materials": { "floor": $1 },
  "meshes": [ { "path": "$root/scenes/cornell-box/cornell_box.obj" },
              { "path": "$root/scenes/cornell-glossy/glossy_floor.obj", "material": "floor" } ] }
JSON
}
# Roughness 0.3 (alpha 0.09) and its Phong equivalent n = (2 / alpha^2 - 2) / 4 = 61.2.
scene '{ "type": "glossy", "diffuse": [0.45, 0.45, 0.45], "specular": [0.04, 0.04, 0.04], "exponent": 61.2 }' phong
scene '{ "type": "ggx", "diffuse": [0.47, 0.47, 0.47], "roughness": 0.3 }' ggx
ms() { "$drift" render "$tmp/$1.json" --spp 64 --threads 1 --seed "$2" --out "$tmp/$1.exr" \
         --stats "$tmp/$1.stats.json" > /dev/null 2>&1
       python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['milliseconds']['render'])" "$tmp/$1.stats.json"; }
total_p=0; total_g=0
for i in $(seq 1 "$runs"); do
  p=$(ms phong "$i"); g=$(ms ggx "$i")
  echo "run $i: phong ${p} ms, ggx ${g} ms"
  total_p=$(python3 -c "print($total_p + $p)"); total_g=$(python3 -c "print($total_g + $g)")
done
python3 -c "print('ggx / phong = %.3f (one thread, 96x96, 64 spp, %d runs)' % ($total_g / $total_p, $runs))"
