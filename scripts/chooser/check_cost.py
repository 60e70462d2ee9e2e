#!/usr/bin/env python3
"""The cost model's leave-one-scene-out error by kind of row (scripts/chooser/fit_table.py):
each scene's rows predicted by a model fitted on the fit scenes without it, scaled by the
scene's own pt 1 spp row as --probe scales them; prints the 20th, 50th and 80th percentile of
measured over predicted, fit and judge scenes apart.

    python3 scripts/chooser/check_cost.py ROWS.jsonl --fit corpus-fit.txt [--guided all]
"""
import argparse
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import fit_table as ft  # noqa: E402


def main():
    a = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    a.add_argument("rows")
    a.add_argument("--fit", required=True)
    a.add_argument("--guided", choices=("off", "all", "direct"), default="all")
    a.add_argument("--drift", default="build/release/bin/drift")
    o = a.parse_args()
    ft.set_guided(o.guided)
    scenes = ft.load(o.rows, o.drift)
    fit_names = {os.path.basename(l.strip()).rsplit(".", 1)[0] for l in open(o.fit)
                 if l.strip() and not l.startswith("#")}
    res = {}
    for s in scenes:
        m = ft.fit([t for t in scenes if t is not s and t["name"] in fit_names], {"prior": 1})
        scale, x = ft.probe_scale(m, s), ft.cost_x(s)
        for key, (ms, _) in s["rows"].items():
            if ft.pickable(key) and key in m["cost"][0] and 0.0 < ms < math.inf:
                kind = key[0] if key[0] == ft.GUIDED else ft.group(key)
                role = "fit" if s["name"] in fit_names else "judge"
                res.setdefault((kind, role), []).append(
                    ms / (ft.predict_ms(m["cost"], key, x) * scale))
    print("| rows | scenes | rows | q20 | median | q80 |\n|---|---|---|---|---|---|")
    for (kind, role), r in sorted(res.items()):
        r.sort()
        q = lambda p: r[int(p * (len(r) - 1))]
        print("| %s | %s | %d | %.2f | %.2f | %.2f |" % (kind, role, len(r), q(0.2), q(0.5), q(0.8)))


if __name__ == "__main__":
    sys.exit(main())
