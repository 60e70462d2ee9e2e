#!/usr/bin/env python3
"""Fits what `drift render --budget-ms` adds to its probe-calibrated predictions
(--budget-probe on) from runs on the fit scenes, and writes it into the model:

    python3 scripts/chooser/validate_budget.py --before B --after build/release/bin/drift \\
        --scenes build/corpus/corpus-fit.txt --jsonl fit.jsonl
    python3 scripts/chooser/fit_calibration.py fit.jsonl --model scenes/corpus/chooser.json

For each run of the "after" binary: the ms spent before the choice (T less what it said was
left), the ms the frame and its writes took after it (--stats' total less the load less that),
and its prediction. finish_ms: the median of (taken - predicted) on the path tracer's picks, at
the model's size (each run's scaled by the model's pixels over its own): the writes and
whatever else a one-shot frame pays that the bench's rows did not. calibrated_safety: the
--quantile (0.8) of taken / (predicted + finish) over all picks, so that most fit. Fit on the fit
scenes only: the judge scenes are what validate_budget.py reports on.
"""
import argparse
import json
import re
import sys

QUANTILE = 0.8


def median(v):
    v = sorted(v)
    return (v[len(v) // 2] + v[(len(v) - 1) // 2]) / 2


def main():
    a = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    a.add_argument("runs", help="validate_budget.py --jsonl on the fit scenes")
    a.add_argument("--model", required=True)
    a.add_argument("--quantile", type=float, default=QUANTILE,
                   help="of taken / predicted, the safety (default %g)" % QUANTILE)
    o = a.parse_args()
    model = json.load(open(o.model))
    size = model.get("size", 400)
    runs = []
    for line in open(o.runs):
        c = json.loads(line)
        x = c["after"]
        left = re.search(r"(-?\d+) ms of T left", x.get("line", ""))
        if not x.get("ok") or not left or "nothing is predicted to fit" in x["line"]:
            continue
        taken = x["after_load"] - (c["budget"] - float(left.group(1)))
        scale = size * size / float(c["size"] * c["size"])
        runs.append((x["pick"].startswith("hybrid"), x["pred"], taken, scale))
    pt = [(taken - pred) * scale for hybrid, pred, taken, scale in runs if not hybrid]
    finish = max(median(pt), 0.0) if pt else 0.0
    ratios = sorted(taken / (pred + finish / scale) for _, pred, taken, scale in runs)
    safety = max(ratios[int(o.quantile * (len(ratios) - 1))], 1.0) if ratios else 1.0
    model["finish_ms"] = round(finish, 1)
    model["calibrated_safety"] = {"pt": round(safety, 3), "hybrid": round(safety, 3)}
    with open(o.model, "w") as fh:
        json.dump(model, fh, indent=1)
        fh.write("\n")
    print("%d runs (%d path tracer): finish_ms %.1f at %d px, calibrated_safety %.3f" % (
        len(runs), len(pt), finish, size, safety))


if __name__ == "__main__":
    sys.exit(main())
