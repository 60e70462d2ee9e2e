#!/usr/bin/env python3
"""`drift render --mode hybrid --budget-ms T` as a user runs it, two binaries side by side
(issue 40, s4): for each scene, size and budget, each binary renders once (alternating which
goes first), and the pick, its predicted ms, the measured ms and its FLIP against a reference
(the path tracer at --ref-spp, cached) are recorded.

    python3 scripts/chooser/validate_budget.py --before OLD/drift --after build/release/bin/drift \\
        --scenes build/corpus/corpus-judge.txt [--sizes 128,200] [--budgets 50,100,250,500,1000] \\
        [--ref-spp 256] [--cache /tmp/drift-chooser-refs] [--jsonl out.jsonl]
    python3 scripts/chooser/validate_budget.py --summary out.jsonl

Measured: `wall` (the whole process, from Python: exec, load, accel, choice, frame, writes),
`after_load` (--stats' milliseconds.total less its load: what --budget-probe on counts T
against) and the 1-minute load average before each run. Prints one row per cell and a summary
per binary (and per budget): share within T (after load; whole process), median measured/T,
median FLIP.
"""
import argparse
import json
import os
import re
import subprocess
import sys
import tempfile
import time


def run(cmd):
    t0 = time.monotonic()
    p = subprocess.run(cmd, capture_output=True, text=True)
    return p, 1e3 * (time.monotonic() - t0)


def reference(drift, scene, size, spp, cache):
    name = "%s-%d-%dspp.exr" % (os.path.basename(scene).rsplit(".", 1)[0], size, spp)
    path = os.path.join(cache, name)
    if not os.path.exists(path):
        p, _ = run(["nice", drift, "render", scene, "--width", str(size), "--height", str(size),
                    "--spp", str(spp), "--quiet", "--out", path])
        if p.returncode:
            raise SystemExit("reference of %s failed: %s" % (scene, p.stderr))
    return path


def render(drift, scene, size, budget, ref, tmp):
    out, stats = os.path.join(tmp, "x.exr"), os.path.join(tmp, "x.json")
    for f in (out, stats):
        if os.path.exists(f):
            os.remove(f)
    load = os.getloadavg()[0]
    p, wall = run(["nice", drift, "render", scene, "--width", str(size), "--height", str(size),
                   "--mode", "hybrid", "--budget-ms", str(budget), "--out", out, "--stats", stats])
    line = next((l for l in p.stderr.splitlines() if "--budget-ms" in l), "")
    m = re.search(r"--budget-ms [\d.]+: (.*?) \(predicted (\d+) ms", line)
    cell = {"load_avg": load, "wall": wall, "line": line, "ok": p.returncode == 0,
            "pick": m.group(1) if m else "?", "pred": float(m.group(2)) if m else float("nan")}
    if p.returncode == 0:
        ms = json.load(open(stats))["milliseconds"]
        cell["total"] = ms["total"]
        cell["after_load"] = ms["total"] - ms["load"]
        d = subprocess.run([drift, "diff", ref, out], capture_output=True,
                           text=True).stdout if ref else ""
        fl = re.search(r"^flip\s+([\d.eE+-]+)", d, re.M)
        cell["flip"] = float(fl.group(1)) if fl else float("nan")
    return cell


def median(v):
    v = sorted(x for x in v if x == x)
    return (v[len(v) // 2] + v[(len(v) - 1) // 2]) / 2 if v else float("nan")


def summary(cells, who, label):
    cs = [(c["budget"], c[who]) for c in cells if who in c and c[who]["ok"]]
    n = len(cs)
    if not n:
        return
    within = sum(x["after_load"] <= b for b, x in cs)
    within_wall = sum(x["wall"] <= b for b, x in cs)
    print("| %s | %s | %d | %d/%d (%.0f%%) | %d/%d | %.2f | %.2f | %.3f | %.1f |" % (
        label, who, n, within, n, 100.0 * within / n, within_wall, n,
        median([x["after_load"] / b for b, x in cs]), median([x["wall"] / b for b, x in cs]),
        median([x["flip"] for b, x in cs]), median([x["load_avg"] for b, x in cs])))


def print_summary(cells):
    print("| budget | chooser | cells | within T (after load) | within T (whole process) | "
          "median after-load ms / T | median whole ms / T | median FLIP | median load avg |")
    print("|---|---|---|---|---|---|---|---|---|")
    for who in ("before", "after"):
        summary(cells, who, "all")
    for budget in sorted({c["budget"] for c in cells}):
        for who in ("before", "after"):
            summary([c for c in cells if c["budget"] == budget], who, "%g" % budget)


def main():
    if len(sys.argv) == 3 and sys.argv[1] == "--summary":  # the tables again from --jsonl's
        print_summary([json.loads(l) for l in open(sys.argv[2])])
        return 0
    a = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    a.add_argument("--before", help="without it, the --after binary alone")
    a.add_argument("--after", required=True)
    a.add_argument("--scenes", required=True, help="a list, one scene a line")
    a.add_argument("--sizes", default="128,200")
    a.add_argument("--budgets", default="50,100,250,500,1000")
    a.add_argument("--ref-spp", type=int, default=256, help="0: no reference, no FLIP")
    a.add_argument("--cache", default="/tmp/drift-chooser-refs")
    a.add_argument("--jsonl", help="every cell, one JSON line each")
    o = a.parse_args()
    os.makedirs(o.cache, exist_ok=True)
    scenes = [l.strip() for l in open(o.scenes) if l.strip() and not l.startswith("#")]
    cells = []
    out = open(o.jsonl, "w") if o.jsonl else None
    with tempfile.TemporaryDirectory() as tmp:
        for scene in scenes:
            for size in [int(s) for s in o.sizes.split(",")]:
                ref = reference(o.after, scene, size, o.ref_spp, o.cache) if o.ref_spp > 0 else None
                for i, budget in enumerate(float(b) for b in o.budgets.split(",")):
                    cell = {"scene": os.path.basename(scene), "size": size, "budget": budget}
                    order = ("before", "after") if i % 2 == 0 else ("after", "before")
                    for who in (w for w in order if getattr(o, w)):
                        cell[who] = render(getattr(o, who), scene, size, budget, ref, tmp)
                    cells.append(cell)
                    if out:
                        out.write(json.dumps(cell) + "\n")
                        out.flush()
                    b, f = cell.get("before", {"pick": "-", "pred": 0, "wall": 0}), cell["after"]
                    print("%s %d %g: before %s (pred %g, %.0f after load, %.0f wall, FLIP %.3f) | "
                          "after %s (pred %g, %.0f after load, %.0f wall, FLIP %.3f) | load %.1f" % (
                              cell["scene"], size, budget, b["pick"], b["pred"],
                              b.get("after_load", -1), b["wall"], b.get("flip", -1), f["pick"],
                              f["pred"], f.get("after_load", -1), f["wall"], f.get("flip", -1),
                              f["load_avg"]), file=sys.stderr, flush=True)
    print_summary(cells)


if __name__ == "__main__":
    sys.exit(main())
