#!/usr/bin/env bash
# CLI test for `drift bench rays`: drift and raw Embree must agree on every hit, including
# light shapes (two quads, a disk and a sphere, which drift numbers per light and raw Embree
# per geometry). $1 is the drift binary. Speed is not checked here (docs/benchmarks.md).
set -u
drift="$1"
source "$(dirname "$0")/common.sh"
box="$(cd "$(dirname "$0")/../../scenes/cornell-box" && pwd)/cornell_box.obj"

cat >"$tmp/lights.json" <<JSON
{ "version": 1,
  "camera": { "position": [278, 273, -800], "target": [278, 273, 0], "fov_y": 39.3,
              "width": 64, "height": 48 },
  "meshes": [ { "path": "$box" } ],
  "lights": [
    { "type": "quad", "corner": [100, 500, 100], "edge_u": [100, 0, 0], "edge_v": [0, 0, 100], "radiance": 5 },
    { "type": "quad", "corner": [300, 500, 300], "edge_u": [100, 0, 0], "edge_v": [0, 0, 100], "radiance": 5 },
    { "type": "disk", "center": [278, 400, 200], "normal": [0, -1, 0], "radius": 40, "radiance": 5 },
    { "type": "sphere", "center": [150, 300, 300], "radius": 30, "radiance": 5 } ] }
JSON

expect 0 "$drift" bench rays --help
expect 0 "$drift" bench rays "$tmp/lights.json" --seconds 0.02 --repeats 1 --json
grep -q '"results_match": true' "$tmp/out" || fail "drift and raw Embree agree with light shapes"
expect 2 "$drift" bench rays "$tmp/lights.json" --repeats zero

if [ "$failures" -ne 0 ]; then
    echo "$failures failure(s)" >&2
    exit 1
fi
echo "cli.bench_rays: all checks passed"
