#!/usr/bin/env python3
"""The pick of scripts/chooser/fit_table.py for one scene from a model file, as
`drift render SCENE --mode hybrid --budget-ms T --budget-probe off` makes it from the same
file (tests/cli/test_chooser.sh checks that they agree):

    python3 scripts/chooser/pick.py MODEL FEATURES.json --budget-ms T --pixels P

FEATURES.json: `drift render SCENE --features --quiet`. Prints the pick's row, as the renderer
names it.
"""
import argparse
import json
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import fit_table as ft  # noqa: E402


def main():
    a = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    a.add_argument("model")
    a.add_argument("features")
    a.add_argument("--budget-ms", type=float, required=True)
    a.add_argument("--pixels", type=float, required=True, help="the frame's width x height")
    o = a.parse_args()
    m = json.load(open(o.model))
    feats = json.load(open(o.features))
    f = [feats[k] for k in m["features"]]
    # The renderer scales each prediction by pixels / size^2 and compares it with T; the same
    # as comparing the prediction at the model's size with T x size^2 / pixels.
    budget = o.budget_ms * m["size"] ** 2 / o.pixels
    key, _, _, _ = ft.choose(ft.from_json(m), f, budget, m.get("pt_margin", 1.0))
    print(ft.to_pick(key, None, None)["row"])


if __name__ == "__main__":
    sys.exit(main())
