#!/usr/bin/env bash
# Frame and per-pass ms of the hybrid frame at 400x400, 2 threads, two binaries interleaved:
#   bench/experiments/framespeed.sh OLD_DRIFT NEW_DRIFT [VPLS] [RUNS]
# prints the median of each figure and the ratio old/new (> 1: the new binary is faster).
set -euo pipefail
old=$1 new=$2 vpls=${3:-256} runs=${4:-5}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
for i in $(seq "$runs"); do
    for b in old new; do
        bin=$old; [ "$b" = new ] && bin=$new
        "$bin" render --mode hybrid --width 400 --height 400 --threads 2 --ism-vpls "$vpls" \
            --frames 5 --stats "$tmp/$b.$i.json" --out "$tmp/$b.exr" --quiet >/dev/null
    done
done
python3 - "$tmp" "$runs" <<'PY'
import json, statistics, sys
tmp, runs = sys.argv[1], int(sys.argv[2])
def figs(b):
    out = {}
    for i in range(1, runs + 1):
        d = json.load(open(f"{tmp}/{b}.{i}.json"))
        row = {"frame": d["milliseconds"]["frame"]}
        row.update({k: v["ms"] for k, v in d["passes"].items() if v["ms"] > 0})
        row["indirect"] = d["effect_ms"]["indirect"]
        for k, v in row.items():
            out.setdefault(k, []).append(v)
    return {k: statistics.median(v) for k, v in out.items()}
o, n = figs("old"), figs("new")
print(f"{'figure':14} {'old ms':>8} {'new ms':>8} {'old/new':>8}")
for k in o:
    if k in n:
        print(f"{k:14} {o[k]:8.1f} {n[k]:8.1f} {o[k] / n[k]:8.2f}")
PY
