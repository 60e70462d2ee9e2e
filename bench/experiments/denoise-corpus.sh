#!/usr/bin/env bash
# The denoisers over the whole corpus (docs/denoiser.md, docs/lab/2026-12-07-issue-48-s2.md):
# for each scene of a corpus list, a reference (drift render, REF_SPP samples, seed 7777) and
# the denoiser's inputs at 1, 4 and 16 spp (seed 0; bench/experiments/denoise_lab.c, each
# spp its own render, as drift render --spp N makes it), then ꟻLIP of raw, à-trous, --denoise on and regression against the
# reference, one Markdown row a scene and spp:
#   | NAME-SPP.bin | spp | raw | atrous | on | regression | on / raw | on ms |
# Usage (after cmake --build build/release --target drift_cli and scripts/corpus/build.sh):
#   OUT=/tmp/dn bash bench/experiments/denoise-corpus.sh build/corpus/corpus.txt
# Environment: OUT (work folder, kept: references and inputs are reused), REF_SPP (256), SIZE
# (320x240), THREADS (2); NOSPLIT=1 filters the beauty as one (no direct part apart);
# INDVG=1 filters the rest variance-guided (session 2's filter); SIGL1, SIGL, SIGLI, RESSIG,
# ITER, SIGA, SIGN, SIGZ, METHOD, NOFF set the params (denoise_lab.c).
set -euo pipefail
root="$(cd "$(dirname "$0")/../.." && pwd)"
list=${1:?usage: denoise-corpus.sh CORPUS.txt}
out=${OUT:-/tmp/denoise-corpus}
ref_spp=${REF_SPP:-256}
size=${SIZE:-320x240}
w=${size%x*} h=${size#*x}
export THREADS=${THREADS:-2}
mkdir -p "$out/refs" "$out/in"
LIBS=$(sed 's/.*bin\/drift *//' "$root/build/release/CMakeFiles/drift_cli.dir/link.txt" |
    sed "s#libdrift.a#$root/build/release/libdrift.a#")
# shellcheck disable=SC2086
cc -O2 -std=c11 -I"$root/include" -I"$root/build/release/generated/include" \
    "$root/bench/experiments/denoise_lab.c" $LIBS -lstdc++ -lm -o "$out/denoise_lab"
args=()
while read -r scene; do
    name=$(basename "$scene") name=${name%%.*}
    ref="$out/refs/$name-ref.exr"
    [ -f "$ref" ] || nice "$root/build/release/bin/drift" render "$scene" --width "$w" --height "$h" \
        --threads "$THREADS" --checkpoint 0 --quiet --spp "$ref_spp" --seed 7777 --out "$ref" >/dev/null
    [ -f "$out/in/$name-16.bin" ] || nice "$out/denoise_lab" dump "$scene" "$w" "$h" 1,4,16 0 "$out/in/$name"
    for spp in 1 4 16; do args+=("$ref" "$out/in/$name-$spp.bin"); done
done <"$list"
echo "| scene | spp | raw | atrous | on | regression | on / raw | on ms |"
echo "|---|---|---|---|---|---|---|---|"
nice "$out/denoise_lab" eval "${args[@]}"
