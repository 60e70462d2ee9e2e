#!/usr/bin/env bash
# SIGTERM is handled like Ctrl-C (issue 18; schedulers and mpirun send SIGTERM): the render
# stops, writes the partial image and its stats, and exits 143 (128 + SIGTERM). $1: drift.
set -u
drift="$1"
source "$(dirname "$0")/common.sh"

"$drift" render --spp 100000 --width 64 --height 64 --threads 1 --checkpoint 0 \
    --out "$tmp/term.exr" --stats "$tmp/term.json" >"$tmp/out" 2>"$tmp/err" &
pid=$!
for i in $(seq 300); do # until it renders (a loaded machine can take seconds to get there)
    grep -q "spp, depth" "$tmp/err" && break
    sleep 0.1
done
sleep 1
kill -TERM "$pid"
wait "$pid"
status=$?
[ "$status" -eq 143 ] || fail "SIGTERM: the render exited $status, expected 143"
[ -s "$tmp/term.exr" ] && [ -s "$tmp/term.png" ] || fail "SIGTERM: no partial image written"
grep -q "interrupted" "$tmp/err" || fail "SIGTERM: the render did not say it was interrupted"
python3 -c "import json; s=json.load(open('$tmp/term.json')); assert 0 < s['spp'] < 100000, s" ||
    fail "SIGTERM: the stats do not show a partial spp"

if [ "$failures" -ne 0 ]; then
    echo "$failures failure(s)" >&2
    exit 1
fi
echo "cli.signals: all checks passed"
