#!/usr/bin/env python3
"""Fits the budget table (issue 40, part 5, a first step) from `drift bench frontier --corpus
... --json` output and validates it leave-one-scene-out.

    python3 scripts/chooser/fit_table.py ROWS.jsonl [--fit LIST] [--out TABLE.json]

ROWS.jsonl: one JSON object a scene (the bench's --json lines: scene, rows of family, name, ms,
FLIP). The model is a table: for each budget, the one combination (a hybrid row, or the path
tracer plain, denoised or at reduced resolution) with the lowest geometric-mean FLIP ratio to
each scene's best row within the budget, a combination over the budget on a scene counting as
a ratio of 3. It uses no scene features yet: it is the baseline a feature-based chooser must
beat. --fit LIST (a corpus-fit.txt) fits the table on those scenes only and reports the others
as unseen. Validation: each scene's pick is fitted without that scene (leave-one-scene-out);
the regret of a cell is the picked row's FLIP over the best row's in hindsight within the
budget. Prints a table scene x budget and a summary line a budget.
"""
import argparse
import json
import math
import os
import sys

OVER = 3.0  # the ratio a combination over the budget on a scene counts as


def load(path):
    scenes = []
    for line in open(path):
        line = line.strip()
        if line.startswith("{"):
            d = json.loads(line)
            rows = {(r["family"], r["name"]): (r["ms"], r["flip"]) for r in d["rows"]}
            scenes.append((d["scene"], rows))
    return scenes


def best_within(rows, budget, families=None):
    cands = [(f, key) for key, (ms, f) in rows.items()
             if ms <= budget and (families is None or key[0] in families)]
    return min(cands) if cands else (None, None)


PT = {"pt", "pt+atrous", "pt-low", "pt-low+atrous"}


def fit(scenes, budget):
    keys = set()
    for _, rows in scenes:
        keys.update(rows)
    best, best_score = None, math.inf
    for key in sorted(keys):
        logs = 0.0
        for _, rows in scenes:
            top, _ = best_within(rows, budget)
            if top is None:
                continue
            ms, f = rows.get(key, (math.inf, math.inf))
            logs += math.log(f / top if ms <= budget and f < math.inf else OVER)
        if logs < best_score:
            best, best_score = key, logs
    return best


def main():
    p = argparse.ArgumentParser()
    p.add_argument("rows")
    p.add_argument("--fit", help="a list of the scenes to fit on (corpus-fit.txt)")
    p.add_argument("--budgets", default="50,100,250,500,1000")
    p.add_argument("--out", help="write the table fitted on every fit scene as JSON")
    a = p.parse_args()
    budgets = [float(b) for b in a.budgets.split(",")]
    scenes = load(a.rows)
    fit_set = None
    if a.fit:
        fit_set = {os.path.realpath(l.strip()) for l in open(a.fit) if l.strip()}
    name = lambda s: os.path.basename(s).split(".")[0]
    is_fit = lambda s: fit_set is None or os.path.realpath(s) in fit_set
    print("| scene | fit? | " + " | ".join("%g ms: pick, FLIP, regret, beats best pt" % b for b in budgets) + " |")
    print("|---|---|" + "---|" * len(budgets))
    stats = {b: {"regret": [], "beats": 0, "cells": 0, "unseen_regret": [], "unseen_beats": 0, "unseen": 0} for b in budgets}
    for i, (path, rows) in enumerate(scenes):
        train = [s for j, s in enumerate(scenes) if j != i and is_fit(s[0])]
        cells = []
        for b in budgets:
            key = fit(train, b)
            top, _ = best_within(rows, b)
            pt, _ = best_within(rows, b, PT)
            ms, f = rows.get(key, (math.inf, math.inf)) if key else (math.inf, math.inf)
            if ms > b:  # over budget here: the renderer falls back to the best pt row
                f, key = (pt, ("fallback", "best pt")) if pt is not None else (math.inf, key)
            regret = f / top if top else math.inf
            beats = pt is not None and f < pt or (pt is None and f < math.inf)
            st = stats[b]
            st["regret"].append(regret)
            st["beats"] += beats
            st["cells"] += 1
            if not is_fit(path):
                st["unseen_regret"].append(regret)
                st["unseen_beats"] += beats
                st["unseen"] += 1
            cells.append("%s %s, %.3f, %.2f, %s" % (key[0], key[1], f, regret, "yes" if beats else "no"))
        print("| %s | %s | %s |" % (name(path), "fit" if is_fit(path) else "unseen", " | ".join(cells)))
    print()
    print("| budget | median regret (all) | chosen beats the best pt (all) | median regret (unseen) | beats (unseen) |")
    print("|---|---|---|---|---|")
    med = lambda v: sorted(v)[len(v) // 2] if v else float("nan")
    for b in budgets:
        st = stats[b]
        print("| %g ms | %.2f | %d / %d | %.2f | %d / %d |" % (b, med(st["regret"]), st["beats"], st["cells"],
                                                     med(st["unseen_regret"]), st["unseen_beats"], st["unseen"]))
    if a.out:
        table = {"comment": "fitted by scripts/chooser/fit_table.py from %s" % a.rows,
                 "budgets": {("%g" % b): list(fit([s for s in scenes if is_fit(s[0])], b)) for b in budgets}}
        json.dump(table, open(a.out, "w"), indent=1)


if __name__ == "__main__":
    sys.exit(main())
