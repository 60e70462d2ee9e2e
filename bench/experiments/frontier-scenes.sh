#!/usr/bin/env bash
# The equal-time frontier on four scenes at a small size (docs/frontier.md): each scene's
# Markdown tables on stdout and in docs/figures/frontier_<scene>.md, its CSV and SVG plot in
# docs/figures/frontier_<scene>.{csv,svg}; then each scene's per-budget table and plot
# replace the block between the frontier-scenes markers of docs/frontier.md. Every hybrid row
# at 1 and 4 anti-aliasing passes; SIR rows at 1, 4 and 16 iterations.
# References are cached in out/ (the first run renders them: ~1-2 min each on 2 threads).
#   BIN=build/release/bin/drift bash bench/experiments/frontier-scenes.sh [SIZE]   (default 160)
set -eu
bin=${BIN:-drift}
size=${1:-160}
root="$(cd "$(dirname "$0")/../.." && pwd)"
fig="$root/docs/figures"
names=()
for scene in cornell-box/cornell_box.json cornell-glossy/cornell_glossy.json \
    plants-blinds/plants_blinds.json breakfast-room/breakfast_room.json; do
    name=$(basename "$scene" .json)
    names+=("$name")
    "$bin" bench frontier "$root/scenes/$scene" --size "$size" --ref-spp 256 --runs 1 \
        --vpls 64,256,1024 --aaf-spp 1,2 --aa 1,4 --sir-iterations 1,4,16 \
        --budgets 25,50,100,250,500,1000 --threads 2 --cache "$root/out" \
        --csv "$fig/frontier_$name.csv" --svg "$fig/frontier_$name.svg" | tee "$fig/frontier_$name.md"
done
python3 - "$root" "$size" "${names[@]}" <<'PY'
import re, sys
root, size, names = sys.argv[1], sys.argv[2], sys.argv[3:]
doc, fig = root + "/docs/frontier.md", root + "/docs/figures"
parts = []
for name in names:
    text = open(f"{fig}/frontier_{name}.md").read()
    title = text.splitlines()[0].lstrip("# ").strip().replace(root + "/", "")
    budget = text[text.index("| budget ms |"):].strip()
    pt1 = re.search(r"^\| pt \| 1 spp \| ([0-9.]+) \|", text, re.M)
    parts.append(f"### {name} ({size}×{size})\n\n{title}; the path tracer's 1 spp took "
                 f"{pt1.group(1) if pt1 else '?'} ms in this run. Every row: "
                 f"[frontier_{name}.md](figures/frontier_{name}.md), "
                 f"[.csv](figures/frontier_{name}.csv).\n\n{budget}\n\n"
                 f"![FLIP against ms, {name}](figures/frontier_{name}.svg)\n")
body = open(doc).read()
begin, end = "<!-- frontier-scenes:begin -->", "<!-- frontier-scenes:end -->"
i, j = body.index(begin) + len(begin), body.index(end)
open(doc, "w").write(body[:i] + "\n" + "\n".join(parts) + body[j:])
PY
