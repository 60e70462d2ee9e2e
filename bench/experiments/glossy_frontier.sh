#!/bin/bash
# Glossy Cornell box at 400x400, 2 threads: pt 1 spp interleaved with hybrid rows varying the
# reflections / indirect technique. Prints ms (from --stats), ms / pt-1spp ms, and FLIP vs REF.
# usage: bench/experiments/glossy_frontier.sh [DRIFT] [REF.exr]
D=${1:-build/release/bin/drift}; REF=${2:-/work/ref400/cornell_glossy.exr}
S=scenes/cornell-glossy/cornell_glossy.json; O=out/g; mkdir -p $O
ms() { python3 -c "import json,sys;d=json.load(open('$1'));m=d['milliseconds'];print(m.get('frame',m.get('render')))"; }
run() { # name args...
  n=$1; shift
  $D render $S --width 400 --height 400 --threads 2 --max-depth 8 "$@" --out $O/$n.exr --stats $O/$n.json >/dev/null 2>&1
  f=$($D diff $REF $O/$n.exr 2>&1 | awk '$1=="flip"{print $2}')
  echo "$n $(ms $O/$n.json) $f"
}
H="--mode hybrid --shadows hard"
for r in isg envmap aaf sharp blur; do
  run pt1 --mode reference --spp 1
  run ism128-$r $H --indirect ism --ism-vpls 128 --reflections $r
  run ir64-$r $H --indirect ir --ism-vpls 64 --reflections $r
done
# micro-rendering indirect (--indirect micro) measured ~390x pt 1 spp, FLIP 0.202: left out.
run pt1 --mode reference --spp 1
