#!/usr/bin/env bash
# Renders every (effect, technique) of the hybrid frame at a small size, plus a few combined
# frames and a SIR refinement, into OUTDIR with the drift binary BIN. Run it with the binary
# before and after a refactor and compare the folders with `cmp` (bench/experiments/technique-compare.sh):
# a refactor that changes no image leaves every file byte-identical.
#   bash bench/experiments/technique-images.sh BIN OUTDIR [SCENE]
set -euo pipefail
bin=$1
out=$2
scene=${3:-$(dirname "$0")/../../scenes/cornell-glossy/cornell_glossy.json}
mkdir -p "$out"
size=(--width 48 --height 36 --spp 4 --threads 2 --quiet)
effects=(shadows reflections dof indirect)
# The technique names come from the binary itself: `drift render --help` lists them, one
# "  --EFFECT T  a (default), b or c" line an effect (tools/cli_options.c prints those lines
# from the technique table; the pre-refactor binary printed the same format by hand).
for effect in "${effects[@]}"; do
  techniques=$("$bin" render --help | grep -E "^  --$effect T" | sed -E 's/.*  (.*)/\1/;s/\(default\)//g;s/,| or / /g')
  for t in $techniques; do
    "$bin" render "$scene" --mode hybrid "${size[@]}" --"$effect" "$t" \
      --out "$out/$effect-$t.exr" --aov "$out/$effect-$t.aov.exr" >/dev/null
  done
done
"$bin" render "$scene" --mode hybrid "${size[@]}" --shadows pcss --reflections envmap --dof post \
  --indirect ambient --out "$out/combo-raster.exr" --aov "$out/combo-raster.aov.exr" >/dev/null
"$bin" render "$scene" --mode hybrid "${size[@]}" --shadows isg --reflections isg --dof isg \
  --isg-layers 2 --out "$out/combo-isg.exr" --aov "$out/combo-isg.aov.exr" >/dev/null
"$bin" render "$scene" --mode hybrid "${size[@]}" --shadows aaf --reflections aaf --indirect aaf \
  --max-depth 4 --out "$out/combo-aaf.exr" --aov "$out/combo-aaf.aov.exr" >/dev/null
"$bin" render "$scene" --mode hybrid "${size[@]}" --shadows aaf --indirect aaf --aaf-sampler random \
  --aaf-sampling uniform --out "$out/combo-aaf-random.exr" >/dev/null
"$bin" render "$scene" --mode hybrid "${size[@]}" --shadows pcss --reflections envmap --dof post \
  --refine sir --budget 200 --refine-iterations 3 --out "$out/combo-sir.exr" >/dev/null
"$bin" render "$scene" "${size[@]}" --out "$out/reference.exr" --checkpoint 0 >/dev/null
ls "$out" | wc -l
