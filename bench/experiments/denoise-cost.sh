#!/usr/bin/env bash
# The denoiser's cost against 2 spp of the render (issue 48): each corpus scene of list.txt
# (one path a line) at SIZE (default 320x240), 2 threads, 1 and 4 spp, 3 runs; prints denoise / (render x 2 / spp).
# usage: bench/experiments/denoise-cost.sh LIST [DRIFT]   (OUT: where the stats go)
set -u
list=$1
B=${2:-build/release/bin/drift}
OUT=${OUT:-/tmp/denoise-cost}
SIZE=${SIZE:-320x240}
mkdir -p "$OUT"
while read -r s; do
  n=$(basename "${s%.*}")
  for spp in 1 4; do
    for k in 1 2 3; do
      "$B" render "$s" --width "${SIZE%x*}" --height "${SIZE#*x}" --threads 2 --spp $spp --denoise on --quiet --checkpoint 0 --out "$OUT/o.exr" --stats "$OUT/$n-$spp-$k.json" > /dev/null 2>&1 || echo "fail $n"
    done
  done
done < "$list"
python3 - "$OUT" <<'PY'
import json,glob,statistics,os,sys
rows={}
for f in glob.glob(sys.argv[1] + '/*-*-*.json'):
    b=os.path.basename(f)[:-5]; n,spp,k=b.rsplit('-',2)
    m=json.load(open(f))['milliseconds']
    rows.setdefault((n,int(spp)),[]).append(m['denoise']/(m['render']*2/int(spp)))
over=0
for (n,spp),v in sorted(rows.items()):
    med=statistics.median(v); print(f"{n:16s} {spp} spp  denoise / 2 spp: median {med:.2f}  max {max(v):.2f}"); over+= max(v)>1
print("rows with a run over 1:", over, "of", len(rows))
PY
