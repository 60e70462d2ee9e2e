#!/usr/bin/env python3
"""Measures what a one-shot hybrid frame pays once, technique by technique, and writes it into
the chooser's model (the "setup_ms" table tools/render_choose.c adds to a hybrid candidate's
predicted frame under --budget-probe on).

    python3 scripts/chooser/measure_setup.py --fit build/corpus/corpus-fit.txt \\
        --model scenes/corpus/chooser.json [--drift build/release/bin/drift] [--size 128]

The bench's hybrid rows (drift bench frontier) are warm frames: their set-up (VPLs and the
imperfect shadow maps' points, PCSS's maps, the environment's filter) is left out, but a
one-shot `drift render --budget-ms` pays it. For each fit scene, `drift render --mode hybrid
--frames 2 --stats` of the base row (hard shadows, no indirect) and of each technique on its
own on top of it; the set-up is the first frame less the warm one (--stats' setup_ms.frame).
A technique's entry is its median over the scenes, less the base's, in ms at --size (>= 0).
These are wall ms at the machine's load of the moment: the table records the mean 1-minute
load average over the runs ("load") and the cores ("cores"), from which the renderer rescales
them to its own load.
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile

BASE = ["--shadows", "hard", "--indirect", "none"]
# What a candidate's row names, and the flags that render it alone on top of the base (the
# bench's rows: 1024 VPLs, AAF at 1 spp).
TECHNIQUES = {
    ("shadows", "pcss"): ["--shadows", "pcss"],
    ("shadows", "isg"): ["--shadows", "isg"],
    ("shadows", "aaf"): ["--shadows", "aaf", "--spp", "1"],
    ("indirect", "ambient"): ["--indirect", "ambient"],
    ("indirect", "ism"): ["--indirect", "ism", "--ism-vpls", "1024"],
    ("indirect", "ir"): ["--indirect", "ir", "--ism-vpls", "1024"],
    ("indirect", "aaf"): ["--indirect", "aaf", "--spp", "1"],
    ("environment_filter", "4"): ["--env-filter", "4"],
}


LOADS = []


def setup_ms(drift, scene, size, flags, tmp):
    LOADS.append(os.getloadavg()[0])
    stats = os.path.join(tmp, "s.json")
    cmd = ["nice", drift, "render", scene, "--width", str(size), "--height", str(size), "--mode",
           "hybrid", "--frames", "2", "--quiet", "--out", os.path.join(tmp, "x.exr"), "--stats",
           stats] + BASE + flags
    subprocess.run(cmd, check=True, capture_output=True)
    return max(json.load(open(stats))["setup_ms"]["frame"], 0.0)


def median(v):
    v = sorted(v)
    return (v[len(v) // 2] + v[(len(v) - 1) // 2]) / 2


def main():
    a = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    a.add_argument("--fit", required=True)
    a.add_argument("--model", required=True)
    a.add_argument("--drift", default="build/release/bin/drift")
    a.add_argument("--size", type=int, default=128)
    o = a.parse_args()
    scenes = [l.strip() for l in open(o.fit) if l.strip() and not l.startswith("#")]
    per = {k: [] for k in TECHNIQUES}
    base = []
    with tempfile.TemporaryDirectory() as tmp:
        for s in scenes:
            b = setup_ms(o.drift, s, o.size, [], tmp)
            base.append(b)
            for k, flags in TECHNIQUES.items():
                # a later flag overrides the base's
                per[k].append(max(setup_ms(o.drift, s, o.size, flags, tmp) - b, 0.0))
            print("%s: base %.1f ms, %s" % (os.path.basename(s), b, ", ".join(
                "%s %s %.0f" % (k[0], k[1], per[k][-1]) for k in TECHNIQUES)), file=sys.stderr)
    table = {"size": o.size, "load": round(sum(LOADS) / len(LOADS), 1), "cores": os.cpu_count(),
             "base": round(median(base), 1)}
    for (effect, name), v in per.items():
        table.setdefault(effect, {})[name] = round(median(v), 1)
    model = json.load(open(o.model))
    model["setup_ms"] = table
    with open(o.model, "w") as fh:
        json.dump(model, fh, indent=1)
        fh.write("\n")
    print(json.dumps(table))


if __name__ == "__main__":
    sys.exit(main())
