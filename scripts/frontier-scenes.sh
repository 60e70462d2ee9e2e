#!/usr/bin/env bash
# The equal-time frontier on four scenes at a small size (docs/frontier.md): each scene's
# Markdown tables on stdout and in docs/figures/frontier_<scene>.md, its CSV and SVG plot in
# docs/figures/frontier_<scene>.{csv,svg}. Every hybrid row at 1 and 4 anti-aliasing passes.
# References are cached in out/ (the first run renders them: ~1-2 min each on 2 threads).
#   BIN=build/release/bin/drift bash scripts/frontier-scenes.sh [SIZE]   (default 160)
set -eu
bin=${BIN:-drift}
size=${1:-160}
root="$(cd "$(dirname "$0")/.." && pwd)"
for scene in cornell-box/cornell_box.json cornell-glossy/cornell_glossy.json \
    plants-blinds/plants_blinds.json breakfast-room/breakfast_room.json; do
    name=$(basename "$scene" .json)
    "$bin" bench frontier "$root/scenes/$scene" --size "$size" --ref-spp 256 --runs 1 \
        --vpls 64,256,1024 --aaf-spp 1,2 --aa 1,4 --budgets 25,50,100,250,500,1000 \
        --threads 2 --cache "$root/out" --csv "$root/docs/figures/frontier_$name.csv" \
        --svg "$root/docs/figures/frontier_$name.svg" | tee "$root/docs/figures/frontier_$name.md"
done
