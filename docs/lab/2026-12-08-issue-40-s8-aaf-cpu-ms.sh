#!/usr/bin/env bash
# Issue 40 (session 8, aaf): the CPU-time cost of a warm hybrid frame of the Breakfast Room at
# 400x400, the frontier's rows (ef 4): (CPU of 3 frames - CPU of 1) / 2 frames / 2 threads.
# CPU time, unlike wall time, barely moves with the shared machine's load; it is a lower bound
# on a quiet machine's wall ms (idle waits of the threads are not counted).
cd "$(dirname "$0")/../.."
S=scenes/breakfast-room/breakfast_room.json
B=build/release/bin/drift
common="--mode hybrid --width 400 --height 400 --threads 2 --max-depth 8 --reflections none --dof none --occlusion none --glare none --env-filter 4 --env-scale 2 --ism-vpls 1024 --out ${TMPDIR:-/tmp}/aaf-cpu-ms.exr"
cpu() { /usr/bin/time -f "%U %S" nice $B render $S $common "$@" 2>&1 >/dev/null | tail -1 | awk '{print $1+$2}'; }
row() { name="$1"; shift; c1=$(cpu --frames 1 "$@"); c3=$(cpu --frames 3 "$@"); echo "$name|$(python3 -c "print('%.1f' % (($c3-$c1)/2/2*1000))")|$(uptime | sed 's/.*average: //')"; }
for rep in 1 2; do
for s in hard pcss isg; do
  row "$s + ism 1024 VPLs ef 4" --shadows $s --indirect ism
  row "$s + ir 1024 VPLs ef 4" --shadows $s --indirect ir
  for n in 1 2 4; do row "$s + aaf $n spp ef 4" --shadows $s --indirect aaf --spp $n; done
done
for n in 1 2 4; do
  row "aaf + ism 1024 VPLs $n spp ef 4" --shadows aaf --indirect ism --spp $n
  row "aaf + ir 1024 VPLs $n spp ef 4" --shadows aaf --indirect ir --spp $n
  row "aaf + aaf $n spp ef 4" --shadows aaf --indirect aaf --spp $n
done
done
