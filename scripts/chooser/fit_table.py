#!/usr/bin/env python3
"""Fits the technique chooser (issue 40) from `drift bench frontier --corpus ... --json` and
validates it leave-one-scene-out.

    python3 scripts/chooser/fit_table.py ROWS.jsonl [--fit corpus-fit.txt] \\
        [--model scenes/corpus/chooser.json] [--drift build/release/bin/drift]

ROWS.jsonl: the bench's --json lines, one a scene (scene, features, rows of family, name, ms,
FLIP). Scenes without features get them from `drift render SCENE --features`.

Two choosers, both judged leave-one-scene-out (each scene's pick fitted without it):
- table: for each budget the one combination with the lowest geometric-mean FLIP ratio to each
  training scene's best row within the budget (over the budget on a scene counts as 3): no
  scene features, the baseline;
- nearest (what `drift render --budget-ms` runs): the training scene nearest in standardised
  features, and the row that was best there within the budget.
The regret of a cell is the chosen row's FLIP over the best row's in hindsight within the budget;
a chosen row that takes longer than the budget on the scene itself is marked `over`. Only rows
the renderer can run are picked: hybrid frames, the path tracer plain or through a-trous.
--model writes the nearest chooser fitted on every --fit scene (all, without --fit).
"""
import argparse
import json
import math
import os
import re
import subprocess
import sys

OVER = 3.0
PICKABLE = {"hybrid", "pt", "pt+atrous"}
PT = {"pt", "pt+atrous", "pt-low", "pt-low+atrous"}
FEATURES = ["log_triangles", "log_lights", "area_share", "delta_share", "environment",
            "glossy_share", "emissive_share", "lens", "depth_range"]


def load(path, drift):
    scenes = []
    for line in open(path):
        line = line.strip()
        if not line.startswith("{"):
            continue
        try:
            d = json.loads(line)
        except json.JSONDecodeError:
            print("fit_table.py: %s: an unfinished line left out" % path, file=sys.stderr)
            continue
        rows = {(r["family"], r["name"]): (r["ms"], r["flip"]) for r in d["rows"]}
        feats = d.get("features")
        if feats is None:
            out = subprocess.run([drift, "render", d["scene"], "--features", "--quiet"],
                                 capture_output=True, text=True, check=True).stdout
            feats = json.loads(out)
        scenes.append({"size": d.get("size", 400), "path": d["scene"], "name": os.path.basename(d["scene"]).split(".")[0],
                       "rows": rows, "features": [feats[k] for k in FEATURES]})
    return scenes


def lookup(rows, key):
    """The row `key` on a scene; a row with the environment filter on a scene without an
    environment is the same row without it (the filter has no light to filter there)."""
    if key in rows:
        return rows[key]
    plain = (key[0], re.sub(r" ef \d+", "", key[1]))
    return rows.get(plain, (math.inf, math.inf))


def best_within(rows, budget, families=None):
    c = [(f, key) for key, (ms, f) in rows.items()
         if ms <= budget and (families is None or key[0] in families)]
    return min(c) if c else (None, None)


def fit_table(train, budget):
    keys = set()
    for s in train:
        keys.update(k for k in s["rows"] if k[0] in PICKABLE)
    best, score = None, math.inf
    for key in sorted(keys):
        logs = 0.0
        for s in train:
            top, _ = best_within(s["rows"], budget)
            if top is None:
                continue
            ms, f = lookup(s["rows"], key)
            logs += math.log(f / top if ms <= budget else OVER)
        if logs < score:
            best, score = key, logs
    return best


def scales(train):
    out = []
    for k in range(len(FEATURES)):
        v = [s["features"][k] for s in train]
        m = sum(v) / len(v)
        out.append(max(math.sqrt(sum((x - m) ** 2 for x in v) / len(v)), 0.1))
    return out


def nearest(train, feats, sc):
    return min(train, key=lambda s: sum(((a - b) / w) ** 2 for a, b, w in zip(s["features"], feats, sc)))


MARGIN = 1.0  # a row is picked from a neighbour when it took at most MARGIN x the budget there


def pick_nearest(train, scene, budget):
    n = nearest(train, scene["features"], scales(train))
    return best_or_fastest(n["rows"], MARGIN * budget)[1], n["name"]


def best_or_fastest(rows, budget):
    """The best pickable row within the budget, else the fastest pickable row (its FLIP, key)."""
    f, key = best_within(rows, budget, PICKABLE)
    if key is None:
        c = [(ms, k) for k, (ms, fl) in rows.items() if k[0] in PICKABLE]
        if c:
            key = min(c)[1]
            f = rows[key][1]
    return f, key


def to_pick(key, ms, flip):
    fam, name = key
    if fam in ("pt", "pt+atrous"):
        return {"kind": "pt", "row": "%s %s" % (fam, name), "spp": int(name.split()[0]),
                "denoise": fam == "pt+atrous", "ms": ms, "flip": flip}
    m = re.match(r"(\w+) \+ (\w+)(.*)$", name)
    p = {"kind": "hybrid", "row": name, "shadows": m.group(1), "indirect": m.group(2), "ms": ms, "flip": flip}
    rest = m.group(3)
    for pat, field, conv in ((r" (\d+) VPLs", "vpls", int), (r"VPLs (?:\S+ )*?(?:\d+ )?spp", None, None),
                             (r" (\d+) spp", "spp", int), (r" ls (\d+)", "light_samples", int),
                             (r" ef (\d+)", "environment_filter", int), (r" aa (\d+)", "aa", int)):
        if field:
            mm = re.search(pat, rest)
            if mm:
                p[field] = conv(mm.group(1))
    p["gather_scale"] = 2 if " g2" in rest else 1
    p["no_near_field"] = " nf off" in rest
    p.setdefault("light_samples", 8)
    p["environment_scale"] = 2 if "environment_filter" in p else 1
    return p


def main():
    a = argparse.ArgumentParser()
    a.add_argument("rows")
    a.add_argument("--fit")
    a.add_argument("--budgets", default="50,100,250,500,1000")
    a.add_argument("--model")
    a.add_argument("--drift", default="build/release/bin/drift")
    a.add_argument("--margin", type=float, default=1.0,
                   help="pick a neighbour's best row within this share of the budget (default 1; "
                        "0.7, 0.5 and 0.35 had higher leave-one-out regret, lab notes)")
    o = a.parse_args()
    global MARGIN
    MARGIN = o.margin
    budgets = [float(b) for b in o.budgets.split(",")]
    scenes = load(o.rows, o.drift)
    fit_set = {os.path.realpath(l.strip()) for l in open(o.fit) if l.strip()} if o.fit else None
    is_fit = lambda s: fit_set is None or os.path.realpath(s["path"]) in fit_set
    print("| scene | role | " + " | ".join("%g ms" % b for b in budgets) + " |")
    print("|---|---|" + "---|" * len(budgets))
    st = {(c, b, u): [] for c in ("table", "nearest") for b in budgets for u in (0, 1)}
    for s in scenes:
        train = [t for t in scenes if t is not s and is_fit(t)]
        cells = []
        for b in budgets:
            top, _ = best_within(s["rows"], b)
            pt, _ = best_within(s["rows"], b, PT)
            cell = []
            for chooser in ("nearest", "table"):
                if chooser == "nearest":
                    key, via = pick_nearest(train, s, b)
                else:
                    key, via = fit_table(train, b), None
                ms, f = lookup(s["rows"], key) if key else (math.inf, math.inf)
                regret = f / top if top else math.inf
                beats = f < pt if pt is not None else f < math.inf
                rec = (regret, beats, ms <= b)
                st[(chooser, b, 0)].append(rec)
                if not is_fit(s):
                    st[(chooser, b, 1)].append(rec)
                if chooser == "nearest":
                    cell.append("%s %s (via %s) %.3f, regret %.2f%s%s" % (
                        key[0] if key else "-", key[1] if key else "", via, f, regret,
                        "" if ms <= b else ", over", ", beats pt" if beats else ""))
            cells.append("; ".join(cell))
        print("| %s | %s | %s |" % (s["name"], "fit" if is_fit(s) else "judge", " | ".join(cells)))
    print("\n| budget | chooser | cells | median regret | mean regret | beats the best pt | within budget | unseen: cells, median regret, beats pt |")
    print("|---|---|---|---|---|---|---|---|")
    med = lambda v: sorted(v)[len(v) // 2] if v else float("nan")
    for b in budgets:
        for c in ("nearest", "table"):
            a_, u = st[(c, b, 0)], st[(c, b, 1)]
            fin = [r[0] for r in a_ if r[0] < math.inf]
            print("| %g | %s | %d | %.2f | %.2f | %d | %d | %d, %.2f, %d |" % (
                b, c, len(a_), med([r[0] for r in a_]), sum(fin) / len(fin) if fin else float("nan"),
                sum(r[1] for r in a_), sum(r[2] for r in a_), len(u), med([r[0] for r in u]), sum(r[1] for r in u)))
    if o.model:
        train = [s for s in scenes if is_fit(s)]
        model = {"comment": "The technique chooser of drift render --budget-ms (tools/render_choose.c), "
                            "fitted by scripts/chooser/fit_table.py from %s: for each fitted scene its "
                            "features and, a budget, the best row the renderer can run." % os.path.basename(o.rows),
                 "size": train[0]["size"], "margin": MARGIN, "features": FEATURES, "scale": scales(train), "scenes": []}
        for s in train:
            picks = {}
            for b in budgets:
                f, key = best_or_fastest(s["rows"], MARGIN * b)
                if key:
                    picks["%g" % b] = to_pick(key, s["rows"][key][0], f)
            model["scenes"].append({"name": s["name"], "features": s["features"], "picks": picks})
        with open(o.model, "w") as fh:
            json.dump(model, fh, indent=1)


if __name__ == "__main__":
    sys.exit(main())
