#!/usr/bin/env bash
# Strong scaling of mpirun -n N drift render (issue 19, docs/distributed.md): interleaved
# rounds of the plain build (-DDRIFT_MPI=OFF), the MPI build under mpirun -n 1, 2 (and 4 with
# FOUR=1, oversubscribed on 2 cores); each figure is the stats' milliseconds.render (rank 0's
# render phase, without mpirun's start-up), every EXR is cmp'd against the plain one. Prints
# each round and the medians of 1 rank / plain and 1 rank / N ranks.
#   MPI=build/release/bin/drift PLAIN=build/plain/bin/drift bash scripts/mpi-scaling.sh
# Options (environment): ROUNDS (5), SIZE (256), SPP (64), FOUR (0), SCENE (the built-in box).
set -u
mpi=${MPI:-build/release/bin/drift}
plain=${PLAIN:-build/plain/bin/drift}
rounds=${ROUNDS:-5}
size=${SIZE:-256}
spp=${SPP:-64}
mpirun=(mpirun --oversubscribe --allow-run-as-root)
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
args=(${SCENE:-} --spp "$spp" --width "$size" --height "$size" --threads 1 --quiet --checkpoint 0)
ms() { python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['milliseconds']['render'])" "$1"; }
run() { # name, command...
    local name=$1
    shift
    "$@" "${args[@]}" --out "$dir/$name.exr" --stats "$dir/$name.json" >"$dir/$name.log" 2>&1 ||
        { echo "$name failed: $(cat "$dir/$name.log")" >&2; exit 1; }
    if [ "$name" != plain ] && ! cmp -s "$dir/plain.exr" "$dir/$name.exr"; then
        echo "$name: not the plain build's bytes" >&2
        exit 1
    fi
    ms "$dir/$name.json"
}
ranks=(1 2)
[ "${FOUR:-0}" = 1 ] && ranks+=(4)
echo "# $size x $size, $spp spp, --threads 1; ms of the render phase; load: $(cut -d' ' -f1-3 /proc/loadavg)"
printf "%-6s %10s" round plain
for n in "${ranks[@]}"; do printf " %10s" "$n rank(s)"; done
printf " %12s" "1r/plain"
for n in "${ranks[@]:1}"; do printf " %10s" "1r/${n}r"; done
echo
: >"$dir/ratios"
for r in $(seq "$rounds"); do
    p=$(run plain "$plain" render)
    declare -A t=()
    for n in "${ranks[@]}"; do
        t[$n]=$(run "n$n" "${mpirun[@]}" -n "$n" "$mpi" render)
    done
    printf "%-6s %10.0f" "$r" "$p"
    for n in "${ranks[@]}"; do printf " %10.0f" "${t[$n]}"; done
    vals=("$p")
    for n in "${ranks[@]}"; do vals+=("${t[$n]}"); done # in rank order (t's keys are not)
    line=$(python3 -c "import sys; v=[float(x) for x in sys.argv[1:]]; print(' '.join('%.3f' % (v[1] / x) for x in [v[0]] + v[2:]))" "${vals[@]}")
    echo "$line" >>"$dir/ratios"
    for x in $line; do printf " %10s" "$x"; done
    echo
done
python3 - "$dir/ratios" "${ranks[@]}" <<'PY'
import statistics, sys
rows = [[float(x) for x in l.split()] for l in open(sys.argv[1])]
names = ["1 rank / plain"] + ["speed-up %s ranks (1 rank / %s ranks)" % (n, n) for n in sys.argv[3:]]
for i, name in enumerate(names):
    col = [r[i] for r in rows]
    print("median %s: %.3f (min %.3f, max %.3f)" % (name, statistics.median(col), min(col), max(col)))
PY
echo "# load after: $(cut -d' ' -f1-3 /proc/loadavg)"
