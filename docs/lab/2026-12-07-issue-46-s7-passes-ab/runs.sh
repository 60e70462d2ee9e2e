#!/bin/bash
# runs.sh OLD NEW: the bench's post DOF and glare rows, old and new binaries alternately; one
# thread (process CPU time, least of 3), then two (wall clock, least of 5). JSON into $OUT.
old=$1; new=$2; out=${OUT:-/tmp/runs7}; mkdir -p $out; cd "$(dirname "$0")/../../.."
for t in 1 2; do f=$([ $t = 1 ] && echo 3 || echo 5); for r in 1 2 3; do for b in old new; do
  bin=$old; [ $b = new ] && bin=$new
  nice $bin bench frame scenes/cornell-bunny/cornell_bunny.json --floors --frames $f \
    --passes "post dof,glare conv" --threads $t --json > $out/t$t-r$r-$b.json
done; done; done
