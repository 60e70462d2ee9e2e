#!/usr/bin/env bash
# Strong scaling of mpirun -n N drift render (issue 19, docs/distributed.md): interleaved
# rounds of the plain build (-DDRIFT_MPI=OFF) and the MPI build under mpirun -n 1, 2 (and 4
# with FOUR=1: oversubscribed on a 2-core machine). Each EXR is cmp'd against the plain one.
# Two figures a run:
#   ms   the stats' milliseconds.render (rank 0's render phase, without mpirun's start-up):
#        the speed-up asked for, meaningful on a quiet machine only;
#   cpu  the largest CPU time (user + sys, /usr/bin/time) of any one rank: what the run would
#        take with a core to itself for each rank; a bound that holds under load, blind to
#        time a rank spends waiting for another.
# Prints each round and the medians of 1 rank / plain and of 1 rank / N ranks for both.
#   MPI=build/release/bin/drift PLAIN=build/plain/bin/drift bash bench/experiments/mpi-scaling.sh
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
# run NAME RANKS: "ms cpu" of one render (RANKS 0: the plain build, no mpirun).
run() {
    local name=$1 n=$2 timed=(/usr/bin/time -a -o "$dir/$1.cpu" -f "%U %S")
    rm -f "$dir/$name.cpu"
    if [ "$n" = 0 ]; then
        "${timed[@]}" "$plain" render "${args[@]}" --out "$dir/$name.exr" --stats "$dir/$name.json"
    else
        "${mpirun[@]}" -n "$n" "${timed[@]}" "$mpi" render "${args[@]}" --out "$dir/$name.exr" \
            --stats "$dir/$name.json"
    fi >"$dir/$name.log" 2>&1 || { echo "$name failed: $(cat "$dir/$name.log")" >&2; exit 1; }
    if [ "$n" != 0 ] && ! cmp -s "$dir/plain.exr" "$dir/$name.exr"; then
        echo "$name: not the plain build's bytes" >&2
        exit 1
    fi
    python3 -c "import json,sys; ms=json.load(open(sys.argv[1]))['milliseconds']['render']
cpu=max(float(u)+float(s) for u,s in (l.split() for l in open(sys.argv[2]) if l.strip()))
print('%.1f %.3f' % (ms, cpu))" "$dir/$name.json" "$dir/$name.cpu"
}
ranks=(1 2)
[ "${FOUR:-0}" = 1 ] && ranks+=(4)
echo "# $size x $size, $spp spp, --threads 1; load average before: $(cut -d' ' -f1-3 /proc/loadavg)"
printf "%-5s %-4s %10s" round what plain
for n in "${ranks[@]}"; do printf " %10s" "$n rank(s)"; done
printf " %9s" "1r/plain"
for n in "${ranks[@]:1}"; do printf " %9s" "1r/${n}r"; done
echo
: >"$dir/ratios"
for r in $(seq "$rounds"); do
    ms=() cpu=()
    read -r m c < <(run plain 0) && ms+=("$m") && cpu+=("$c")
    for n in "${ranks[@]}"; do
        read -r m c < <(run "n$n" "$n") && ms+=("$m") && cpu+=("$c")
    done
    [ "${#ms[@]}" -eq $((${#ranks[@]} + 1)) ] || exit 1
    for what in ms cpu; do
        declare -n v=$what
        line=$(python3 -c "import sys; v=[float(x) for x in sys.argv[1:]]; print(' '.join('%.3f' % (v[1] / x) for x in [v[0]] + v[2:]))" "${v[@]}")
        echo "$what $line" >>"$dir/ratios"
        printf "%-5s %-4s" "$r" "$what"
        for x in "${v[@]}"; do printf " %10s" "$x"; done
        for x in $line; do printf " %9s" "$x"; done
        echo
    done
done
python3 - "$dir/ratios" "${ranks[@]}" <<'PY'
import statistics, sys
rows = [l.split() for l in open(sys.argv[1])]
names = ["1 rank / plain"] + ["speed-up %s ranks (1 rank / %s ranks)" % (n, n) for n in sys.argv[3:]]
for what in ("ms", "cpu"):
    table = [[float(x) for x in r[1:]] for r in rows if r[0] == what]
    for i, name in enumerate(names):
        col = [r[i] for r in table]
        print("median %-3s %s: %.3f (min %.3f, max %.3f)" % (what, name, statistics.median(col), min(col), max(col)))
PY
echo "# load average after: $(cut -d' ' -f1-3 /proc/loadavg)"
