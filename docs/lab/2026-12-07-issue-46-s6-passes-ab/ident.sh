#!/bin/bash
# ident.sh OLD NEW: the same images from both binaries, byte for byte.
old=$1; new=$2; d=${IDENT_DIR:-/tmp/ident}; rm -rf $d; mkdir -p $d; cd "$(dirname "$0")/../../.."
s=scenes/cornell-bunny/cornell_bunny.json
fail=0
run() { # name args...
  n=$1; shift
  for b in old new; do
    bin=$old; [ $b = new ] && bin=$new
    nice $bin "$@" --out $d/$n.$b.exr --quiet > $d/$n.$b.log 2>&1 || { echo "$n $b failed"; cat $d/$n.$b.log | tail -3; fail=1; }
  done
  if cmp -s $d/$n.old.exr $d/$n.new.exr; then echo "$n identical"; else echo "$n DIFFERS"; fail=1; fi
}
for t in 1 2; do
  run atrous-bunny-t$t render $s --spp 4 --width 320 --height 240 --threads $t --denoise atrous
  run atrous-breakfast-t$t render scenes/breakfast-room/breakfast_room.json --spp 2 --width 300 --height 200 --threads $t --denoise atrous
  run atrous-open-t$t render scenes/open-glossy/open_glossy.json --spp 2 --width 300 --height 200 --threads $t --denoise atrous
  run hybrid-glare-t$t render $s --mode hybrid --width 320 --height 240 --threads $t --glare static --aov
done
for b in old new; do bin=$old; [ $b = new ] && bin=$new; nice $bin glare $d/atrous-bunny-t1.old.exr --psf-size 128 --out $d/glare.$b.exr > /dev/null 2>&1; done; cmp -s $d/glare.old.exr $d/glare.new.exr && echo "glare-file identical" || { echo "glare-file DIFFERS"; fail=1; }
exit $fail
