#!/usr/bin/env bash
# The occlusion effect's techniques against its reference in whole frames: each scene rendered
# by the hybrid frame with --occlusion T and with --occlusion reference (the environment's
# diffuse light ray-traced at REF_SPP shadow rays a pixel); every other term is the same in
# both frames (same techniques and seed), so the FLIP between them is the technique's error.
# A second reference adds --indirect reference (the first diffuse bounce, path-traced): the
# truth of SSDO's bounce, "FLIP+b". `none` is the frame's own ray-traced environment term at
# --light-samples 8. "occl ms" is the occlusion effect's own time in the last of --frames 3
# (warm), the figure to match techniques by; the frame time is beside it.
#   BIN=build/release/bin/drift bash bench/experiments/occlusion-quality.sh [SCENE...]
# TECHS overrides the rows: specs name[,opt...] with name none|ssao|gtao|ssdo and opts n=N
# (--occlusion-samples), s=K (--occlusion-steps), c=N (--occlusion-cameras), l=2
# (--occlusion-layers), b (--ssdo-bounce on), e.g. TECHS="ssao,n=32 ssdo,n=8,s=4,b".
set -u
bin=${BIN:-drift}
size=(--width "${WIDTH:-240}" --height "${HEIGHT:-180}" --threads 2 --quiet --frames 3)
out=${OUT:-$(mktemp -d)}
mkdir -p "$out"
scenes=("$@")
[ ${#scenes[@]} -gt 0 ] || scenes=(scenes/ssdo-real/cornell_bunny_dragon.json
  scenes/ssdo-real/breakfast_courtyard.json scenes/ssdo-real/plants_forest.json
  scenes/ssdo-blocks/ssdo_blocks.json scenes/ssdo-open/ssdo_open.json)
read -r -a techs <<< "${TECHS:-none ssao gtao ssdo ssdo,b}"
printf "%-22s %-18s %8s %9s %8s %8s\n" scene technique "occl ms" "frame ms" FLIP FLIP+b
for s in "${scenes[@]}"; do
  name=$(basename "$s" .json)
  [ -f "$out/$name-ref.exr" ] || "$bin" render "$s" --mode hybrid "${size[@]}" --frames 1 \
    --occlusion reference --spp "${REF_SPP:-256}" --out "$out/$name-ref.exr" 2>/dev/null ||
    { echo "$name: reference failed"; continue; }
  [ -f "$out/$name-refb.exr" ] || "$bin" render "$s" --mode hybrid "${size[@]}" --frames 1 \
    --occlusion reference --indirect reference --max-depth 2 --spp "${REF_SPP:-256}" \
    --out "$out/$name-refb.exr" 2>/dev/null || { echo "$name: bounce reference failed"; continue; }
  for t in "${techs[@]}"; do
    IFS=, read -r -a parts <<< "$t"
    args=(--occlusion "${parts[0]}")
    for o in "${parts[@]:1}"; do
      case $o in
        n=*) args+=(--occlusion-samples "${o#n=}") ;;
        s=*) args+=(--occlusion-steps "${o#s=}") ;;
        c=*) args+=(--occlusion-cameras "${o#c=}") ;;
        l=*) args+=(--occlusion-layers "${o#l=}") ;;
        b) args+=(--ssdo-bounce on) ;;
        *) echo "unknown option $o in $t"; exit 2 ;;
      esac
    done
    tag=${t//[,=]/_}
    "$bin" render "$s" --mode hybrid "${size[@]}" "${args[@]}" --out "$out/$name-$tag.exr" \
      --stats "$out/$name-$tag.json" 2>/dev/null || { echo "$name $t failed"; continue; }
    ms=$(python3 -c "import json;d=json.load(open('$out/$name-$tag.json'));print(d['effect_ms']['occlusion'], d['milliseconds']['frame'])")
    flip=$("$bin" diff "$out/$name-ref.exr" "$out/$name-$tag.exr" | awk '/^flip/{print $2}')
    flipb=$("$bin" diff "$out/$name-refb.exr" "$out/$name-$tag.exr" | awk '/^flip/{print $2}')
    read -r occl frame <<< "$ms"
    printf "%-22s %-18s %8.1f %9.1f %8.4f %8.4f\n" "$name" "$t" "$occl" "$frame" "$flip" "$flipb"
  done
done
