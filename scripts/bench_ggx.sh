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
# CPU milliseconds of the whole process (user + system): on a shared machine wall time counts
# the other processes' turns too, CPU time far less.
ms() { /usr/bin/time -f "%U %S" -o "$tmp/$1.time" "$drift" render "$tmp/$1.json" --spp 64 \
         --threads 1 --seed "$2" --out "$tmp/$1.exr" > /dev/null 2>&1
       python3 -c "import sys; u, s = open(sys.argv[1]).read().split()[-2:]; print(1000 * (float(u) + float(s)))" "$tmp/$1.time"; }
pairs=""
for i in $(seq 1 "$runs"); do
  p=$(ms phong "$i"); g=$(ms ggx "$i")
  echo "run $i: phong ${p} ms, ggx ${g} ms"
  pairs="$pairs $p,$g"
done
# On a shared machine one run can stall: the median of the per-run ratios is reported with
# the ratio of the totals.
python3 - $pairs <<'PY'
import statistics, sys
pairs = [tuple(map(float, a.split(","))) for a in sys.argv[1:]]
ratios = sorted(g / p for p, g in pairs)
total = sum(g for _, g in pairs) / sum(p for p, _ in pairs)
print("ggx / phong: median %.3f, totals %.3f, runs %s (one thread, 96x96, 64 spp)"
      % (statistics.median(ratios), total, " ".join("%.3f" % r for r in ratios)))
PY
