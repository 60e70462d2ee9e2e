#!/usr/bin/env bash
# The Fig. 5.8 trend of the thesis (issue 14): the ISM's error as points per VPL and ISM
# resolution grow, 256 light paths, on the Cornell box (or SCENE): the NRMSE of ism's I
# against ir's (the same VPLs with exact visibility) and the RMSE of I against the path
# tracer. Writes OUT.csv and OUT.svg (default docs/figures/ism_fig58).
#   BIN=build/release/bin/drift bash bench/experiments/ism-fig58.sh [SCENE] [OUT]
set -eu
bin=${BIN:-drift}
root="$(cd "$(dirname "$0")/../.." && pwd)"
scene=${1:-$root/scenes/cornell-box/cornell_box.json}
out=${2:-$root/docs/figures/ism_fig58}
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
echo "map,points,nrmse_vs_ir,rmse_vs_pt,ms" > "$out.csv"
for map in 32 64 128; do
    for points in 256 1024 4096 16384; do
        "$bin" bench ism "$scene" --size 128 --ref-spp 64 --vpls 256 --spp 1 --points "$points" \
            --map "$map" --threads 2 --json > "$tmp/run.json"
        python3 - "$tmp/run.json" "$map" "$points" >> "$out.csv" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
ism = next(r for r in d["rows"] if r["what"] == "ism")
ir = next(r for r in d["rows"] if r["what"] == "ir")
print(f'{sys.argv[2]},{sys.argv[3]},{ir["nrmse_ism_vs_ir"]},{ism["rmse_indirect"]},{ism["ms"]}')
PY
    done
done
python3 - "$out.csv" "$out.svg" "$(basename "$scene")" <<'PY'
import csv, math, sys
rows = list(csv.DictReader(open(sys.argv[1])))
W, H, L, R, T, B = 560, 380, 70, 20, 40, 50
xs = [math.log2(int(r["points"])) for r in rows]
ymax = max(float(r["nrmse_vs_ir"]) for r in rows) * 1.1 or 1.0
x0, x1 = min(xs), max(xs)
px = lambda p: L + (math.log2(p) - x0) / (x1 - x0) * (W - L - R)
py = lambda v: T + (ymax - v) / ymax * (H - T - B)
out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{W}" height="{H}" font-family="sans-serif" font-size="12">',
       '<rect width="100%" height="100%" fill="white"/>',
       f'<text x="{L}" y="20" font-size="14">ISM NRMSE against exact-visibility IR, 256 paths: {sys.argv[3]}</text>',
       f'<rect x="{L}" y="{T}" width="{W-L-R}" height="{H-T-B}" fill="none" stroke="black"/>']
for p in sorted({int(r["points"]) for r in rows}):
    out.append(f'<text x="{px(p):.1f}" y="{H-B+16}" text-anchor="middle">{p}</text>')
for k in range(5):
    v = ymax * k / 4
    out.append(f'<line x1="{L}" y1="{py(v):.1f}" x2="{W-R}" y2="{py(v):.1f}" stroke="#eee"/>'
               f'<text x="{L-6}" y="{py(v)+4:.1f}" text-anchor="end">{v:.3f}</text>')
out.append(f'<text x="{(L+W-R)/2}" y="{H-12}" text-anchor="middle">points per VPL (log)</text>')
colours = {"32": "#c62f1f", "64": "#1f63c6", "128": "#2a9d4b"}
for i, (m, c) in enumerate(colours.items()):
    pts = [(int(r["points"]), float(r["nrmse_vs_ir"])) for r in rows if r["map"] == m]
    out.append('<polyline fill="none" stroke="%s" stroke-width="2" points="%s"/>' %
               (c, " ".join(f"{px(p):.1f},{py(v):.1f}" for p, v in pts)))
    out.extend(f'<circle cx="{px(p):.1f}" cy="{py(v):.1f}" r="3" fill="{c}"/>' for p, v in pts)
    out.append(f'<text x="{W-R-110}" y="{T+18+16*i}" fill="{c}">{m}x{m} maps</text>')
out.append('</svg>')
open(sys.argv[2], "w").write("\n".join(out) + "\n")
PY
cat "$out.csv"
