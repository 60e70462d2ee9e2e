"""One line per `drift bench sir --json` row of every JSON file in a folder (used by the
bench_sir_*.sh scripts): error pixels, FLIP, speed-ups, the time split and the ray share."""
import glob
import json
import os
import sys

for path in sorted(glob.glob(os.path.join(sys.argv[1], '*.json'))):
    for row in json.load(open(path))['rows']:
        print(f"{os.path.basename(path)[:-5]:24s} {row['view']:10s} err {row['error_percent']:5.1f}% "
              f"FLIP {row['flip']:.5f} same {row['same_image']!s:5s} speedup {row['speedup']:.2f}x "
              f"to-0.01 {row['speedup_to_flip']:.2f}x PRT {row['prt_ms']:.0f} SIR {row['sir_ms']:.0f} "
              f"(raster {row['raster_ms']:.0f} metrics {row['metrics_ms']:.0f} trace {row['trace_ms']:.0f}) "
              f"rays {row['sir_rays']/row['prt_rays']:.3f} of PRT")
