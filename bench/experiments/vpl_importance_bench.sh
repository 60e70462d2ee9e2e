#!/usr/bin/env bash
# VPL importance (docs/ism.md) on/off, interleaved, against a path-traced reference; prints
# technique, VPLs, importance, frame ms, FLIP. Usage: bench/experiments/vpl_importance_bench.sh [SIZE] [SCENE]
set -euo pipefail
SIZE=${1:-160}
SCENE=${2:-scenes/breakfast-room/breakfast_room.json}
D=${DRIFT:-build/release/bin/drift}
OUT=out/vplimp-$(basename "$SCENE" .json)-$SIZE
mkdir -p "$OUT"
common=(--width "$SIZE" --height "$SIZE" --threads 2 --max-depth 8)
REF=$OUT/ref.exr
[ -f "$REF" ] || "$D" render "$SCENE" --mode reference --spp 256 "${common[@]}" --out "$REF" >/dev/null
ms() { sed -n -e 's/.*(frame \([0-9.]*\) ms).*/\1/p' -e 's/.*(render \([0-9.]*\) s).*/\1 s/p'; }
flip() { "$D" diff "$REF" "$1" | awk '/^flip/ {print $2}'; }
for spp in 1 8; do
  t=$("$D" render "$SCENE" --mode reference --spp $spp "${common[@]}" --out "$OUT/pt$spp.exr" 2>&1 | ms)
  echo "pt $spp spp - $t $(flip "$OUT/pt$spp.exr")"
  t=$("$D" render "$SCENE" --mode reference --spp $spp --denoise atrous "${common[@]}" --out "$OUT/pta$spp.exr" 2>&1 | ms)
  echo "pt+atrous $spp spp - $t $(flip "$OUT/pta$spp.exr")"
done
for ind in ${INDIRECT:-ir ism}; do
  for n in ${VPLS:-256 1024 4096}; do
    for imp in off on; do
      f=$OUT/$ind-$n-$imp.exr
      t=$("$D" render "$SCENE" --mode hybrid --shadows hard --indirect "$ind" --ism-vpls "$n" \
          --ism-vpl-importance "$imp" "${common[@]}" --out "$f" 2>&1 | ms)
      echo "$ind $n $imp $t $(flip "$f")"
    done
  done
done
