#!/usr/bin/env bash
# Equal-time rows on the built-in Cornell box, 400x400, 2 threads: each row's frame (or render)
# milliseconds from its --stats and its FLIP against a 512-spp path-traced reference, rendered
# first into the current folder when it is not there (about 100 s on 2 cores).
#   BIN=build/release/bin/drift bash bench/experiments/frontier-cornell.sh   (run it in an empty folder)
set -u
bin=${BIN:-drift}
[ -f ref512.exr ] || "$bin" render --spp 512 --width 400 --height 400 --threads 2 --quiet \
  --checkpoint 0 --out ref512.exr >/dev/null
row() { # name, args... (hybrid rows render 3 frames: the warm frame's ms, as a viewer sees it)
  local name=$1; shift
  case " $* " in *" --mode hybrid "*) set -- "$@" --frames 3 ;; esac
  "$bin" render --width 400 --height 400 --threads 2 --quiet --checkpoint 0 "$@" --out "$name.exr" --stats "$name.json" >/dev/null 2>&1 || { echo "$name FAILED"; return; }
  local ms=$(python3 -c "import json;d=json.load(open('$name.json'));m=d.get('milliseconds',{});print(m.get('frame', m.get('render', 0)))")
  local flip=$("$bin" diff ref512.exr "$name.exr" | awk '/^flip/{print $2}')
  printf "%-34s %9.1f ms  FLIP %.4f\n" "$name" "$ms" "$flip"
}
for s in 1 2 4 8; do row pt-${s}spp --spp $s; done
row hybrid-default --mode hybrid
row hybrid-hard-ambient --mode hybrid --indirect ambient
for v in 64 256 1024; do row hybrid-hard-ism-$v --mode hybrid --indirect ism --ism-vpls $v --max-depth 8; done
for v in 64 256; do row hybrid-pcss-ism-$v --mode hybrid --shadows pcss --indirect ism --ism-vpls $v --max-depth 8; done
for v in 64 256 1024; do row hybrid-hard-ir-$v --mode hybrid --indirect ir --ism-vpls $v --max-depth 8; done
for v in 64 256; do row hybrid-hard-ism-$v-d3 --mode hybrid --indirect ism --ism-vpls $v --max-depth 3; done
row hybrid-aaf1-ir-256 --mode hybrid --shadows aaf --spp 1 --indirect ir --ism-vpls 256 --max-depth 8
row hybrid-hard-aaf1 --mode hybrid --indirect aaf --spp 1 --max-depth 8
