#!/usr/bin/env bash
# Every diffuse-indirect technique of the hybrid frame on one scene (issue 14's table): hard
# shadows, max depth 2 (one bounce, so every row and the reference carry the same light), each
# row's warm frame ms (the third of --frames 3) and its FLIP and RMSE against a path-traced
# reference of the whole frame. Rows: no indirect light, ambient, AAF (1, 2, 4 spp), SSDO's
# bounce, ir and ism (64 to 4096 VPLs at the defaults, and 1024 at the thesis's 256^2
# maps with 8192 points). Writes OUT.csv (default docs/figures/indirect_<scene>.csv).
#   BIN=build/release/bin/drift bash bench/experiments/indirect-equal-time.sh [SCENE] [OUT] [W] [H] [REF_SPP]
set -eu
bin=${BIN:-drift}
root="$(cd "$(dirname "$0")/../.." && pwd)"
scene=${1:-$root/scenes/cornell-box/cornell_box.json}
name=$(basename "$scene" .json)
out=${2:-$root/docs/figures/indirect_$name}
w=${3:-320}
h=${4:-240}
ref_spp=${5:-256}
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
common=(--width "$w" --height "$h" --threads 2 --quiet --checkpoint 0 --max-depth 2)
"$bin" render "$scene" --mode reference --spp "$ref_spp" "${common[@]}" --out "$tmp/ref.exr"
echo "row,ms,indirect_ms,flip,rmse" > "$out.csv"
row() { # row NAME ARGS...: one hybrid frame, its warm ms and its error
    local label=$1
    shift
    "$bin" render "$scene" --mode hybrid --shadows hard "${common[@]}" --frames 3 "$@" \
        --out "$tmp/row.exr" --stats "$tmp/row.json"
    "$bin" diff "$tmp/ref.exr" "$tmp/row.exr" --json > "$tmp/diff.json"
    python3 - "$tmp/row.json" "$tmp/diff.json" "$label" >> "$out.csv" <<'PY'
import json, sys
s, d = json.load(open(sys.argv[1])), json.load(open(sys.argv[2]))
print(f'{sys.argv[3]},{s["milliseconds"]["frame"]:.1f},{s["effect_ms"]["indirect"]:.1f},'
      f'{d["flip"]:.4f},{d["rmse"]:.4f}')
PY
}
row "none" --indirect none
row "ambient" --indirect ambient
for spp in 1 2 4; do row "aaf $spp spp" --indirect aaf --spp "$spp"; done
row "ssdo bounce" --indirect none --occlusion ssdo --ssdo-bounce on
for v in 64 256 1024 4096; do
    row "ir $v" --indirect ir --ism-vpls "$v"
    row "ism $v" --indirect ism --ism-vpls "$v"
done
row "ism 1024, 256^2 maps, 8192 points" --indirect ism --ism-vpls 1024 --ism-map-size 256 \
    --ism-points 8192
cat "$out.csv"
