#!/usr/bin/env bash
# mpirun -n N drift render (issue 19, docs/distributed.md): 1, 2 and 4 ranks give the same bytes
# as one process (beauty and AOV layers); a rank killed mid-render ends the job non-zero with
# the checkpoint of every merged tile, which resumes to the same bytes; a hung rank is named
# and its job ends the same way; bad input fails once, on every rank, writing nothing.
# $1: drift (built with -DDRIFT_MPI=ON), $2: mpirun.
set -u
drift="$1"
mpirun=("$2" --oversubscribe --allow-run-as-root)
source "$(dirname "$0")/../cli/common.sh"
export ASAN_OPTIONS="${ASAN_OPTIONS:-}:detect_leaks=0" # Open MPI's own allocations at exit

# 48x48: 9 tiles, more than 4 ranks x 2 jobs queued.
base=(--width 48 --height 48 --threads 1 --seed 2 --checkpoint 0 --aov)
small=(--width 48 --height 16 --threads 1 --seed 2 --checkpoint 0 --aov)

expect 0 "$drift" render "${base[@]}" --spp 3 --quiet --out "$tmp/one.exr"
# (3 ranks render the killed and hung jobs below.)
for n in 1 2 4; do
    expect 0 "${mpirun[@]}" -n "$n" "$drift" render "${base[@]}" --spp 3 --quiet \
        --out "$tmp/n$n.exr"
    cmp -s "$tmp/one.exr" "$tmp/n$n.exr" || fail "$n ranks: not the bytes of one process"
done

# rank_pid MPIRUN_PID RANK: the pid of that rank (mpirun's child with its rank in the env).
rank_pid() {
    local c
    for c in $(pgrep -P "$1"); do
        if tr '\0' '\n' <"/proc/$c/environ" 2>/dev/null | grep -qx "OMPI_COMM_WORLD_RANK=$2"; then
            echo "$c"
        fi
    done
}

# start_long OUT: a long 3-rank render of 48x16 (3 tiles) in the background; sets $job once
# it renders.
start_long() {
    "${mpirun[@]}" -n 3 "$drift" render "${small[@]}" --spp 1000000 --out "$1" \
        --stats "${1%.exr}.json" "${@:2}" \
        >"$tmp/out" 2>"$tmp/err" &
    job=$!
    local i
    for i in $(seq 200); do
        grep -q "ranks (" "$tmp/err" && break
        sleep 0.1
    done
    sleep 0.5
}

# A killed rank: rank 0 writes the checkpoint and the partial image, the job ends non-zero
# and mpirun names the rank.
start_long "$tmp/k.exr"
victim=$(rank_pid "$job" 1)
[ -n "$victim" ] || fail "no rank 1 found under mpirun"
kill -KILL $victim
wait "$job"
status=$?
[ "$status" -ne 0 ] || fail "a job with a killed rank exited 0"
grep -q "rank 1" "$tmp/err" || fail "the killed rank is not named: $(cat "$tmp/err")"
[ -s "$tmp/k.ckpt" ] || fail "no checkpoint after a rank died"
grep -q "interrupted at" "$tmp/err" || fail "rank 0 did not say what it kept"
# Resuming it (on 2 ranks) gives the bytes of an uninterrupted one-process render.
most=$(python3 -c "import json; s=json.load(open('$tmp/k.json')); print(s.get('spp_max', s['spp']))" \
    2>/dev/null || echo 0)
expect 0 "${mpirun[@]}" -n 2 "$drift" render "${small[@]}" --spp $((most + 2)) --quiet \
    --out "$tmp/k.exr" --resume "$tmp/k.ckpt"
expect 0 "$drift" render "${small[@]}" --spp $((most + 2)) --quiet --out "$tmp/k1.exr"
cmp -s "$tmp/k.exr" "$tmp/k1.exr" || fail "the resumed job differs from an uninterrupted render"

# A hung rank (stopped): rank 0 names it after --rank-timeout, keeps its work, exits non-zero.
start_long "$tmp/h.exr" --rank-timeout 6
kill -STOP $(rank_pid "$job" 2)
wait "$job"
status=$?
[ "$status" -ne 0 ] || fail "a job with a hung rank exited 0"
grep -q "rank 2 sent nothing for 6 s" "$tmp/err" || fail "the hung rank is not named: $(cat "$tmp/err")"
[ -s "$tmp/h.ckpt" ] && [ -s "$tmp/h.exr" ] || fail "the hung job kept no checkpoint or image"

# Bad input: one message whatever the rank count, nothing written.
expect 2 "${mpirun[@]}" -n 3 "$drift" render --spp zero --out "$tmp/bad.exr"
[ "$(grep -c "expects an integer" "$tmp/err")" -eq 1 ] ||
    fail "a bad option is not reported exactly once: $(cat "$tmp/err")"
expect 1 "${mpirun[@]}" -n 1 "$drift" render "${small[@]}" --spp 1 --out "$tmp/bad.exr" : \
    -n 1 "$drift" render "$tmp/missing.json" "${small[@]}" --spp 1 --out "$tmp/bad.exr"
[ "$(grep -c "rank 1: drift render: cannot load scene" "$tmp/err")" -eq 1 ] ||
    fail "a scene missing on rank 1 is not reported once, naming the rank: $(cat "$tmp/err")"
ls "$tmp" | grep -q '^bad\.' && fail "bad input wrote output: $(ls "$tmp")"

# mpirun -n N drift bench aaf|isg|sir|micro|micro-bounces|ism: the sweep's renders spread over
# the ranks, the same figures as one process (timings aside), printed once by rank 0. micro,
# micro-bounces and ism at 20 pixels wide: references of 2 or more tiles over the ranks.
same_figures() { python3 "$(dirname "$0")/same_figures.py" "$@" >/dev/null || fail "$3: $(python3 "$(dirname "$0")/same_figures.py" "$1" "$2")"; }
scenes="$(dirname "$0")/../../scenes"
bench_aaf=(bench aaf --effect both --spp 1,2 --ref-spp 4 --width 16 --height 12 --timing-size 16x12
    --timing-spp 1 --light-samples 4 --json)
bench_isg=(bench isg --no-table --qwidth 16 --qheight 12 --ref-spp 2 --json)
bench_sir=(bench sir "$scenes/cornell-box/cornell_box.json" --sizes 24x16,16x16 --spp 1 --budget 64
    --json)
bench_micro=(bench micro --size 20 --ref-spp 2 --points 256 --sizes 8 --densities 1,4 --scaling 8
    --json)
bench_bounces=(bench micro-bounces --size 20 --ref-spp 2 --points 128 --micro-size 4 --photons 128
    --bounces 1,2 --json)
bench_ism=(bench ism --size 20 --height 12 --ref-spp 2 --vpls 4,8 --spp 1 --points 16 --map 8 --classic
    --threads 1 --json)
for b in aaf isg sir micro bounces ism; do
    declare -n cmd="bench_$b"
    "$drift" "${cmd[@]}" >"$tmp/$b.json" 2>"$tmp/err" || fail "bench $b failed: $(cat "$tmp/err")"
    ranks=(2)
    [ "$b" = aaf ] && ranks=(2 3) # 3 ranks: items not a multiple of the ranks
    for n in "${ranks[@]}"; do
        "${mpirun[@]}" -n "$n" "$drift" "${cmd[@]}" >"$tmp/$b$n.json" 2>"$tmp/err" ||
            fail "bench $b on $n ranks failed: $(cat "$tmp/err")"
        same_figures "$tmp/$b.json" "$tmp/$b$n.json" "bench $b on $n ranks"
    done
done
# A bad option: one message, whatever the rank count.
expect 2 "${mpirun[@]}" -n 2 "$drift" bench aaf --spp 4,2
[ "$(grep -c "increasing list" "$tmp/err")" -eq 1 ] ||
    fail "a bad bench option is not reported exactly once: $(cat "$tmp/err")"

if [ "$failures" -ne 0 ]; then
    echo "$failures failure(s)" >&2
    exit 1
fi
echo "distributed.mpi: all checks passed"
