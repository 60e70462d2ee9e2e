#!/usr/bin/env bash
# The denoisers against no denoiser (docs/denoiser.md): for each scene, ꟻLIP (drift diff)
# against a high-spp path-traced reference of the raw path tracer and of each --denoise
# choice at each spp, plus the filter's milliseconds beside the cost of 2 spp of that render.
#   BIN=build/release/bin/drift REFS=out/denoise-refs bash bench/experiments/bench-denoise.sh SCENE...
# Options through the environment: SIZE (320x240), SPPS ("1 4 16"), REF_SPP (512), THREADS
# (2), DENOISERS ("atrous on regression"). References are cached in $REFS as NAME-WxH-SPP.exr
# (made on the first run). Prints one Markdown row a scene and spp:
#   | scene | spp | raw | atrous | on | regression | on / raw | on ms | 2 spp ms |
set -eu
bin=${BIN:-drift}
size=${SIZE:-320x240}
spps=${SPPS:-1 4 16}
ref_spp=${REF_SPP:-512}
threads=${THREADS:-2}
denoisers=${DENOISERS:-atrous on regression}
refs=${REFS:-out/denoise-refs}
w=${size%x*} h=${size#*x}
mkdir -p "$refs"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
common=(--width "$w" --height "$h" --threads "$threads" --checkpoint 0 --quiet)
ms_of() { python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["milliseconds"][sys.argv[2]])' "$1" "$2"; }
flip_of() { "$bin" diff "$1" "$2" | awk '$1 == "flip" {printf "%.4f", $2}'; }
header="| scene | spp | raw"
for d in $denoisers; do header+=" | $d"; done
echo "$header | on / raw | on ms | 2 spp ms |"
echo "|---|---|---$(for d in $denoisers; do printf '|---'; done)|---|---|---|"
for scene in "$@"; do
    name=$(basename "$scene") name=${name%%.*}
    ref="$refs/$name-${size}-${ref_spp}.exr"
    if [ ! -f "$ref" ]; then
        "$bin" render "$scene" "${common[@]}" --spp "$ref_spp" --out "$ref" >/dev/null
    fi
    for spp in $spps; do
        "$bin" render "$scene" "${common[@]}" --spp "$spp" --out "$work/raw.exr" \
            --stats "$work/raw.json" >/dev/null
        raw=$(flip_of "$ref" "$work/raw.exr")
        row="| $name | $spp | $raw"
        two=-
        on_flip= on_ms=
        for d in $denoisers; do
            "$bin" render "$scene" "${common[@]}" --spp "$spp" --denoise "$d" \
                --out "$work/$d.exr" --stats "$work/$d.json" >/dev/null
            f=$(flip_of "$ref" "$work/$d.exr")
            row+=" | $f"
            if [ "$d" = on ]; then
                on_flip=$f on_ms=$(ms_of "$work/$d.json" denoise)
                # 2 spp of the same run's render: the cost the filter is held to.
                two=$(python3 -c "print(f'{2 * $(ms_of "$work/$d.json" render) / $spp:.0f}')")
            fi
        done
        ratio=$(python3 -c "print(f'{$on_flip / $raw:.2f}')" 2>/dev/null || echo -)
        printf '%s | %s | %.0f | %s |\n' "$row" "$ratio" "${on_ms:-0}" "$two"
    done
done
