#!/usr/bin/env python3
# same_figures.py A.json B.json: two `drift bench ... --json` outputs hold the same figures,
# timings aside (keys ms, *_ms and the ratios of timings and rates). tests/distributed/test_mpi.sh.
import json, sys

TIMED = {"ms", "speedup", "gathers_per_s", "gather_samples_per_s", "speedup_to_flip", "raster_metrics_time_share", "filter_fraction"}
def strip(v):
    if isinstance(v, dict):
        return {k: strip(x) for k, x in v.items() if k not in TIMED and not k.endswith("_ms")}
    if isinstance(v, list):
        return [strip(x) for x in v]
    return v
a, b = (strip(json.load(open(p))) for p in sys.argv[1:3])
if a != b:
    print("differ:", json.dumps(a)[:400], "\n", json.dumps(b)[:400])
    sys.exit(1)
print("same figures (timings aside)")
