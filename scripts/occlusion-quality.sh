#!/usr/bin/env bash
# The occlusion effect's techniques against its reference in whole frames: each scene rendered
# by the hybrid frame with --occlusion T and with --occlusion reference (the environment's
# diffuse light ray-traced at REF_SPP shadow rays a pixel); every other term is the same in
# both frames (same techniques and seed), so the FLIP between them is the technique's error.
# `none` is the frame's own ray-traced environment term at --light-samples 8.
#   BIN=build/release/bin/drift bash scripts/occlusion-quality.sh [SCENE...]
set -u
bin=${BIN:-drift}
size=(--width "${WIDTH:-240}" --height "${HEIGHT:-180}" --threads 2 --quiet)
out=${OUT:-$(mktemp -d)}
mkdir -p "$out"
scenes=("$@")
[ ${#scenes[@]} -gt 0 ] || scenes=(scenes/ssdo-real/cornell_bunny_dragon.json
  scenes/ssdo-real/breakfast_courtyard.json scenes/ssdo-real/plants_forest.json
  scenes/ssdo-blocks/ssdo_blocks.json scenes/ssdo-open/ssdo_open.json)
printf "%-28s %-12s %10s %8s\n" scene technique "frame ms" FLIP
for s in "${scenes[@]}"; do
  name=$(basename "$s" .json)
  "$bin" render "$s" --mode hybrid "${size[@]}" --occlusion reference --spp "${REF_SPP:-256}" \
    --out "$out/$name-ref.exr" 2>/dev/null || { echo "$name: reference failed"; continue; }
  for t in none ssao gtao ssdo ssdo+bounce; do
    args=(--occlusion "${t%+bounce}")
    [ "$t" = ssdo+bounce ] && args+=(--ssdo-bounce on)
    "$bin" render "$s" --mode hybrid "${size[@]}" "${args[@]}" --out "$out/$name-$t.exr" \
      --stats "$out/$name-$t.json" 2>/dev/null || { echo "$name $t failed"; continue; }
    ms=$(python3 -c "import json;print(json.load(open('$out/$name-$t.json'))['milliseconds']['frame'])")
    flip=$("$bin" diff "$out/$name-ref.exr" "$out/$name-$t.exr" | awk '/^flip/{print $2}')
    printf "%-28s %-12s %10.1f %8.4f\n" "$name" "$t" "$ms" "$flip"
  done
done
