#!/usr/bin/env bash
# --env-denoise off against on (docs/denoiser.md, docs/lab/2026-12-07-issue-48-s2.md): for
# three scenes with an environment, 160x120, 2 threads, path-traced references (256 spp, seed
# 7777) of the whole light and of direct light alone (--max-depth 1), then the hybrid frame with
# the environment filter's 4 passes as the a-trous filter (off) or the variance-guided denoiser
# (on), at --light-samples 1 and 2 (--env-scale 2, the default) and at 1 with --env-scale 1:
#   frame_flip   the default frame against the full reference
#   direct_flip  the frame with --indirect none --reflections none against the direct reference
#                (the environment's shadow rays are most of what differs)
#   env_pass_ms  the unshadowed pass's milliseconds (--stats; noisy on a loaded machine)
# Usage (after cmake --build build/release --target drift_cli):
#   OUT=/tmp/envdn bash bench/experiments/env-denoise.sh [build/release/bin/drift]
set -euo pipefail
root="$(cd "$(dirname "$0")/../.." && pwd)"
drift=${1:-$root/build/release/bin/drift}
out=${OUT:-/tmp/env-denoise}
mkdir -p "$out"
cd "$root"
size=(--width 160 --height 120 --threads 2)
flip() { "$drift" diff "$1" "$2" --json | python3 -c 'import json,sys;print("%.4f"%json.load(sys.stdin)["flip"])'; }
ms() { python3 -c 'import json,sys;print("%.1f"%json.load(open(sys.argv[1]))["passes"]["unshadowed"]["ms"])' "$1"; }
for s in scenes/corpus/dragon_hdri.json scenes/corpus/teapot_studio.json scenes/open-plant/open_plant.json; do
    n=$(basename "$s" .json)
    [ -f "$out/$n-ref.exr" ] || nice "$drift" render "$s" "${size[@]}" --spp 256 --seed 7777 \
        --out "$out/$n-ref.exr" --checkpoint 0 >/dev/null
    [ -f "$out/$n-ref1.exr" ] || nice "$drift" render "$s" "${size[@]}" --spp 256 --seed 7777 \
        --max-depth 1 --out "$out/$n-ref1.exr" --checkpoint 0 >/dev/null
    for cfg in "1 2" "2 2" "1 1"; do
        set -- $cfg
        for dn in off on; do
            tag="$n-ls$1-s$2-$dn"
            knobs=(--light-samples "$1" --env-scale "$2" --env-filter 4 --env-denoise "$dn")
            nice "$drift" render "$s" --mode hybrid "${size[@]}" "${knobs[@]}" \
                --out "$out/$tag.exr" --stats "$out/$tag.json" >/dev/null
            nice "$drift" render "$s" --mode hybrid "${size[@]}" "${knobs[@]}" --indirect none \
                --reflections none --out "$out/$tag-d.exr" >/dev/null
            echo "$n light-samples=$1 env-scale=$2 env-denoise=$dn" \
                "frame_flip=$(flip "$out/$n-ref.exr" "$out/$tag.exr")" \
                "direct_flip=$(flip "$out/$n-ref1.exr" "$out/$tag-d.exr")" \
                "env_pass_ms=$(ms "$out/$tag.json")"
        done
    done
done
