#!/usr/bin/env bash
# --aaf-denoise per pass (docs/aaf.md, docs/lab/2026-12-07-issue-48-s3-aaf.md): for each AAF pass
# (shadows, indirect, reflections) the hybrid frame with that pass AAF and the others held
# fixed (shadows hard, indirect none, reflections none), against the same frame with the pass
# path-traced (`reference`, 256 spp, seed 7777). --max-depth 2 (one bounce, AAF's and the
# reference's). 160x120, 2 threads, AAF at 16 and 4 spp (SPPS="64 16 4": others), four ways:
#   raw     --aaf-filter off: AAF's samples unfiltered
#   aaf     AAF's own filter (the default)
#   denoise --aaf-denoise on: the feature-guided denoiser instead of AAF's filter
#   both    --aaf-denoise both: the denoiser, then AAF's filter
# Prints ꟻLIP and the pass's filter milliseconds (--stats aaf_filter; noisy on a shared machine).
# Usage (after cmake --build build/release --target drift_cli):
#   OUT=/tmp/aafdn bash bench/experiments/aaf-denoise.sh [build/release/bin/drift]
set -euo pipefail
root="$(cd "$(dirname "$0")/../.." && pwd)"
drift=${1:-$root/build/release/bin/drift}
out=${OUT:-/tmp/aaf-denoise}
mkdir -p "$out"
cd "$root"
size=(--width 160 --height 120 --threads 2 --max-depth 2)
flip() { "$drift" diff "$1" "$2" --json | python3 -c 'import json,sys;print("%.4f"%json.load(sys.stdin)["flip"])'; }
ms() { python3 -c 'import json,sys;print("%.1f"%json.load(open(sys.argv[1]))["passes"]["aaf_filter"]["ms"])' "$1"; }
scenes=${SCENES:-"scenes/cornell-box/cornell_box.json:shadows,indirect scenes/cornell-glossy/cornell_glossy.json:shadows,indirect,reflections scenes/corpus/veach_mi.json:shadows,reflections scenes/breakfast-room/breakfast_room.json:shadows,indirect,reflections"}
for entry in $scenes; do
    s=${entry%%:*}
    n=$(basename "$s" .json)
    for pass in ${entry#*:}; do
        pass=${pass//,/ }
        for p in $pass; do
            fixed=(--shadows hard --indirect none --reflections none)
            ref="$out/$n-$p-ref.exr"
            [ -f "$ref" ] || nice "$drift" render "$s" --mode hybrid "${size[@]}" "${fixed[@]}" \
                --"$p" reference --spp 256 --seed 7777 --out "$ref" >/dev/null 2>&1
            for spp in ${SPPS:-16 4}; do
                for way in raw aaf denoise both; do
                    case $way in
                    raw) knobs=(--aaf-filter off) ;;
                    aaf) knobs=() ;;
                    denoise) knobs=(--aaf-denoise on) ;;
                    both) knobs=(--aaf-denoise both) ;;
                    esac
                    tag="$n-$p-$spp-$way"
                    nice "$drift" render "$s" --mode hybrid "${size[@]}" "${fixed[@]}" --"$p" aaf \
                        --spp "$spp" "${knobs[@]}" --out "$out/$tag.exr" --stats "$out/$tag.json" \
                        >/dev/null 2>&1
                    echo "$n pass=$p spp=$spp way=$way flip=$(flip "$ref" "$out/$tag.exr")" \
                        "filter_ms=$(ms "$out/$tag.json")"
                done
            done
        done
    done
done
