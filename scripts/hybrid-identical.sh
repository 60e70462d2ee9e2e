#!/usr/bin/env bash
# Renders `drift render --mode hybrid` with the defaults and with every technique of every
# effect (and knobs of every family) with two drift binaries, and compares the EXRs byte for
# byte: the check of a refactor that must not change an image (issue 44: the families' state
# through their hooks). Prints one line per configuration and exits 1 on any difference.
#   usage: scripts/hybrid-identical.sh BASELINE_DRIFT NEW_DRIFT [OUT_DIR] [SIZE]
#   e.g.   scripts/hybrid-identical.sh /tmp/drift-main build/dev/bin/drift /tmp/ident 48
# 30 configurations x 2 renders at 48x48, --spp 4, 2 threads: minutes on a quiet 2-core
# machine with the ASan build (much longer under load).
set -uo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
base=${1:?baseline drift binary}
new=${2:?new drift binary}
out=${3:-/tmp/hybrid-identical}
size=${4:-48}
mkdir -p "$out/base" "$out/new"
i=0
bad=0
while IFS= read -r line; do
  [ -z "$line" ] && continue
  i=$((i + 1))
  for side in base new; do
    bin=$base
    [ "$side" = new ] && bin=$new
    # shellcheck disable=SC2086 # the line is the options, word-split on purpose
    (cd "$root/scenes" && nice "$bin" render $line --mode hybrid --width "$size" \
      --height "$size" --spp 4 --threads 2 --quiet --out "$out/$side/c$i.exr" \
      >/dev/null 2>"$out/$side/c$i.err") || echo "c$i: $side failed: $line"
  done
  if cmp -s "$out/base/c$i.exr" "$out/new/c$i.exr"; then
    echo "c$i identical: $line"
  else
    echo "c$i DIFFERS: $line"
    bad=1
  fi
done <<LIST
cornell-glossy/cornell_glossy.json
cornell-glossy/cornell_glossy.json --shadows pcf
cornell-glossy/cornell_glossy.json --shadows pcss --contact-shadows on
cornell-glossy/cornell_glossy.json --shadows isg
cornell-glossy/cornell_glossy.json --shadows blur
cornell-glossy/cornell_glossy.json --shadows aaf
cornell-glossy/cornell_glossy.json --shadows reference
cornell-glossy/cornell_glossy.json --reflections envmap
cornell-glossy/cornell_glossy.json --reflections envmap --envmap-parallax box --envmap-size 64
cornell-glossy/cornell_glossy.json --reflections sharp
cornell-glossy/cornell_glossy.json --reflections isg --isg-range plane
cornell-glossy/cornell_glossy.json --reflections blur --blur-radius 2
cornell-glossy/cornell_glossy.json --reflections aaf --aaf-filter off
cornell-glossy/cornell_glossy.json --reflections micro --micro-density 1/4 --micro-points 4096
cornell-glossy/cornell_glossy.json --dof post
cornell-glossy/cornell_glossy.json --dof isg --isg-layers 2
cornell-glossy/cornell_glossy.json --indirect none
cornell-glossy/cornell_glossy.json --indirect ambient
cornell-glossy/cornell_glossy.json --indirect aaf --aaf-sampling uniform
cornell-glossy/cornell_glossy.json --indirect ir --ism-vpls 64
cornell-glossy/cornell_glossy.json --indirect micro --micro-points 4096 --micro-bounces 2
cornell-glossy/cornell_glossy.json --ism-gather-scale 4 --ism-map-size 32 --ism-points 256 --ism-later-paths 10
cornell-glossy/cornell_glossy.json --ism-gather-scale 1 --ism-near-field off --ism-vpl-importance on
ssdo-open/ssdo_open.json
ssdo-open/ssdo_open.json --occlusion ssao --occlusion-cameras 1
ssdo-open/ssdo_open.json --occlusion gtao --occlusion-radius 0.5
ssdo-open/ssdo_open.json --occlusion ssdo --ssdo-bounce on --indirect none
ssdo-open/ssdo_open.json --env-interleave on --light-samples 4
ssdo-open/ssdo_open.json --env-scale 1 --env-filter 0 --aa 2
cornell-glossy/cornell_glossy.json --glare static
LIST
exit "$bad"
