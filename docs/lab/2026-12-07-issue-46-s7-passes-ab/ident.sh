#!/bin/bash
# ident.sh OLD NEW: post DOF's hybrid frames byte for byte (1 and 2 threads, and NEW's 1 against
# its 2); the glare frames (hybrid --glare static, drift glare on an EXR) by drift diff: the FFT's
# rounding changed (tests/unit/test_glare.c bounds it against the direct sum).
old=$1; new=$2; d=${IDENT_DIR:-/tmp/ident7}; rm -rf $d; mkdir -p $d; cd "$(dirname "$0")/../../.."
s=scenes/cornell-bunny/cornell_bunny.json
fail=0
for t in 1 2; do
  for b in old new; do
    bin=$old; [ $b = new ] && bin=$new
    nice $bin render $s --mode hybrid --width 480 --height 270 --threads $t --dof post \
      --out $d/dof-t$t.$b.exr --quiet || fail=1
    nice $bin render $s --mode hybrid --width 480 --height 270 --threads $t --dof post \
      --glare static --out $d/glare-t$t.$b.exr --quiet || fail=1
  done
  cmp -s $d/dof-t$t.old.exr $d/dof-t$t.new.exr && echo "post dof t$t identical" || { echo "post dof t$t DIFFERS"; fail=1; }
  echo "hybrid glare t$t old vs new: $($new diff $d/glare-t$t.old.exr $d/glare-t$t.new.exr --json)"
done
cmp -s $d/glare-t1.new.exr $d/glare-t2.new.exr && echo "new glare frame: 1 and 2 threads identical" || { echo "new glare 1 vs 2 threads DIFFERS"; fail=1; }
for b in old new; do bin=$old; [ $b = new ] && bin=$new
  nice $bin glare $d/dof-t1.old.exr --psf-size 128 --out $d/glare-file.$b.exr > /dev/null 2>&1 || fail=1; done
echo "drift glare (PSF 128) old vs new: $($new diff $d/glare-file.old.exr $d/glare-file.new.exr --json)"
exit $fail
