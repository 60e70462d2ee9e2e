#!/usr/bin/env bash
# Resuming (issue 18): an interrupted reference render leaves FILE.ckpt beside --out; running
# the same command again (or --resume FILE.ckpt) continues it and ends with the same bytes as
# an uninterrupted render. A checkpoint of another render, or a damaged one, is refused
# (exit 2, nothing written). The interrupted image says its tiles' sample counts differ: in
# the message, the stats and the EXR header (and an spp layer). $1: drift binary.
set -u
drift="$1"
source "$(dirname "$0")/common.sh"

# 32x32 = 4 tiles; one thread, so an interruption lands between tiles.
base=(--width 32 --height 32 --threads 1 --seed 3 --checkpoint 0)

# interrupt OUT: a long render to OUT, stopped by SIGTERM once it is rendering.
interrupt() {
    "$drift" render "${base[@]}" --spp 1000000 --out "$1" --stats "${1%.exr}.json" \
        >"$tmp/out" 2>"$tmp/err" &
    local pid=$! i
    for i in $(seq 100); do
        grep -q "spp, depth" "$tmp/err" && break
        sleep 0.1
    done
    sleep 0.3
    kill -TERM "$pid"
    wait "$pid"
    local status=$?
    [ "$status" -eq 143 ] || fail "the interrupted render exited $status, expected 143"
}

# Interrupt until the tiles hold different counts (a stop between passes leaves them even;
# with 4 tiles a stop lands inside a pass 3 times in 4).
for attempt in 1 2 3 4 5 6; do
    rm -f "$tmp"/i.*
    interrupt "$tmp/i.exr"
    grep -q '"spp_max"' "$tmp/i.json" && break
done
[ -s "$tmp/i.ckpt" ] || fail "the interrupted render left no checkpoint i.ckpt"
grep -q "resume from $tmp/i.ckpt" "$tmp/err" || fail "the message does not say how to resume"
if grep -q '"spp_max"' "$tmp/i.json"; then
    grep -q "tiles hold different counts" "$tmp/err" || fail "uneven tiles not said in the message"
    grep -aq "drift.spp_note" "$tmp/i.exr" || fail "uneven tiles not said in the EXR header"
    grep -aq "spp.Y" "$tmp/i.exr" || fail "the interrupted EXR has no spp layer"
    python3 - "$tmp/i.json" <<'PY' || fail "the stats do not hold each tile's count"
import json, sys
s = json.load(open(sys.argv[1]))
assert s["tile_size"] == 16 and len(s["tile_spp"]) == 4, s
assert min(s["tile_spp"]) == s["spp"] < s["spp_max"] == max(s["tile_spp"]), s
PY
else
    fail "six interruptions all left even tiles"
fi
most=$(python3 -c "import json; s=json.load(open('$tmp/i.json')); print(s.get('spp_max', s['spp']))")
total=$((most + 8))

# A checkpoint of other options, or a damaged one, is refused: exit 2, nothing written
# (--resume FILE resuming to the same bytes: distributed.mpi).
cp "$tmp/i.ckpt" "$tmp/keep.ckpt"
expect 2 "$drift" render "${base[@]}" --seed 4 --spp "$total" --quiet --out "$tmp/x.exr" \
    --resume "$tmp/i.ckpt"
grep -q "is of another render (its seed is 3, this run's 4)" "$tmp/err" ||
    fail "a checkpoint of another seed is not refused clearly: $(cat "$tmp/err")"
expect 2 "$drift" render "${base[@]}" --width 48 --spp "$total" --quiet --out "$tmp/i.exr"
grep -q "its size is 32x32, this run's 48x32" "$tmp/err" ||
    fail "the checkpoint beside --out of another size is not refused: $(cat "$tmp/err")"
expect 2 "$drift" render "${base[@]}" --spp 1 --quiet --out "$tmp/x.exr" --resume "$tmp/i.ckpt"
grep -q "more than --spp 1" "$tmp/err" || fail "a checkpoint past --spp is not refused"
head -c 5000 "$tmp/i.ckpt" >"$tmp/cut.ckpt"
expect 2 "$drift" render "${base[@]}" --spp "$total" --quiet --out "$tmp/x.exr" \
    --resume "$tmp/cut.ckpt"
grep -q "cut short or damaged" "$tmp/err" || fail "a cut checkpoint is not refused"
ls "$tmp" | grep -q '^x\.' && fail "a refused resume wrote output: $(ls "$tmp")"
cmp -s "$tmp/i.ckpt" "$tmp/keep.ckpt" || fail "a refused resume changed the checkpoint"

# The same command resumes by itself and matches an uninterrupted render byte for byte;
# the finished render removes its checkpoint.
expect 0 "$drift" render "${base[@]}" --spp "$total" --aov --out "$tmp/i.exr" --stats "$tmp/i.json"
grep -q "resuming from $tmp/i.ckpt" "$tmp/err" || fail "the same command did not resume"
[ -e "$tmp/i.ckpt" ] && fail "the finished render left its checkpoint"
expect 0 "$drift" render "${base[@]}" --spp "$total" --aov --quiet --out "$tmp/full.exr"
cmp -s "$tmp/i.exr" "$tmp/full.exr" || fail "the resumed render differs from an uninterrupted one"
python3 -c "import json; s=json.load(open('$tmp/i.json')); assert s['spp'] == $total and 0 < s['resumed_from_spp'] < $total, s" ||
    fail "the resumed stats do not say where they resumed from"

if [ "$failures" -ne 0 ]; then
    echo "$failures failure(s)" >&2
    exit 1
fi
echo "cli.resume: all checks passed"
