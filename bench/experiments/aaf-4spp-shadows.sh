#!/usr/bin/env bash
# Issue 17's AAF shadows at 4 spp: the equal-error ratio against plain MC before/after, and the
# whole hybrid frame's FLIP with AAF shadows + AAF indirect at 4 spp (160x160, Cornell box).
# Usage: OLD=path/to/old/drift NEW=build/release/bin/drift bash bench/experiments/aaf-4spp-shadows.sh
set -euo pipefail
OLD=${OLD:?old drift binary} NEW=${NEW:-build/release/bin/drift}
T=${TMPDIR:-/tmp}/aaf-4spp; mkdir -p "$T"
B="--effect shadows --spp 4,8,16 --mc-spp 4,8,16,32,64 --ref-spp 1024 --width 160 --height 120 --timing-size 80x80 --timing-spp 4 --threads 2"
for sc in cornell-box/cornell_box.json open-plant/open_plant.json cornell-bunny/cornell_bunny.json; do
    for b in "$OLD" "$NEW"; do echo "== $sc $b"; "$b" bench aaf "scenes/$sc" $B | sed -n 4,7p; done
done
S=scenes/cornell-box/cornell_box.json
"$NEW" render "$S" --mode reference --width 160 --height 160 --spp 256 --max-depth 8 --out "$T/ref.exr" >/dev/null
for b in "$OLD" "$NEW"; do
    "$b" render "$S" --mode hybrid --width 160 --height 160 --shadows aaf --indirect aaf --spp 4 \
        --max-depth 8 --out "$T/f.exr" >/dev/null
    echo "== $b hybrid aaf+aaf 4 spp"; "$NEW" diff "$T/ref.exr" "$T/f.exr" | grep -Ei "^(flip|rmse)"
done
