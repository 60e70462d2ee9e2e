#!/usr/bin/env python3
"""Compares variants of the chooser's quality and cost model (scripts/chooser/fit_table.py)
leave-one-scene-out, so that one is chosen without looking at the judge scenes:

    python3 scripts/chooser/compare_variants.py ROWS.jsonl --fit build/corpus/corpus-fit.txt

For each variant: (1) the SELECTION score, from the fit scenes alone: each fit scene's picks
by a model fitted on the other fit scenes; the score is the mean over those cells of
log(effective regret), where a pick whose measured ms is over the budget has its regret
multiplied by its overrun (ms / budget) and every regret is capped at 4 (a row the bench did
not run on the scene: 4). (2) The judge scenes' figures, reported, not used to choose: each
judge scene's picks by a model fitted on the fit scenes (train fit) and on every other scene
(train all), and their score as the selection score is made (mean log effective regret over
the judge cells). The variant of the lowest selection score is the one to ship; the judge columns
say how it does on scenes it was not chosen on.

--guided off|all|direct: which hybrid+pt rows every variant may pick (fit_table.py --guided).
--baseline ROWS: one more row first, a model fitted on ROWS' fit scenes (the shipped model's
rows; its quality parameters --baseline-prior, k 2, idw, probe, --baseline-guided (off) and
--baseline-norm, as shipped since session 5) judged on these rows' judge scenes: the shipped
model against a refit on the same rows (its fit-scene columns are not leave-one-out, so it has
no selection score).
--probe-safety S: the probe's safety S for both groups, as the renderer's calibrated_safety.
--guided-margin M: the hybrid+pt rows' margin against the path tracer (fit_table.py's).
"""
import argparse
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import fit_table as ft  # noqa: E402

CAP = 4.0


def effective(c):
    r = c["regret"]
    if not r < math.inf:
        return CAP
    if c["ms"] > c["budget"]:
        r *= c["ms"] / c["budget"]
    return min(max(r, 1.0), CAP)


def score(cells):
    return sum(math.log(effective(c)) for c in cells) / len(cells)


# Each variant: a name, the quality parameters over fit_table.QUALITY, --budget-probe (the
# scene's own pt 1 spp row scales every predicted cost, as the renderer's probe does).
VARIANTS = [
    ("diagnosis: k2 idw, the measured ms", {}, "oracle"),
    ("diagnosis: prior 1, kappa 0.5, the measured ms", {"prior": 1.0, "kappa": 0.5}, "oracle"),
    ("s2 (shipped): k2 idw", {}, False),
    ("k2 idw, probe", {}, True),
    ("k3 idw", {"k": 3}, False),
    ("all gauss h1", {"k": 0, "kernel": "gauss", "bandwidth": 1.0}, False),
    ("all gauss h2", {"k": 0, "kernel": "gauss", "bandwidth": 2.0}, False),
    ("k2 idw + prior 0.5", {"prior": 0.5}, False),
    ("k2 idw + prior 1", {"prior": 1.0}, False),
    ("k2 idw + prior 3", {"prior": 3.0}, False),
    ("prior only", {"prior": 1e6}, False),
    ("k2 idw + prior 1, kappa 0.5", {"prior": 1.0, "kappa": 0.5}, False),
    ("k2 idw + prior 1, kappa 1", {"prior": 1.0, "kappa": 1.0}, False),
    ("k2 idw + prior 1, robust", {"prior": 1.0, "robust": True}, False),
    ("all gauss h2 + prior 1, kappa 0.5", {"k": 0, "kernel": "gauss", "bandwidth": 2.0,
                                          "prior": 1.0, "kappa": 0.5}, False),
    ("k2 idw, safety q0.9", {"safety_quantile": 0.9}, False),
    ("k2 idw + prior 1, kappa 0.5, q0.9", {"prior": 1.0, "kappa": 0.5, "safety_quantile": 0.9},
     False),
    ("k2 idw + prior 1, probe", {"prior": 1.0}, True),
    ("k2 idw + prior 1, kappa 0.5, probe", {"prior": 1.0, "kappa": 0.5}, True),
    ("k2 idw + prior 1, kappa 0.5, probe, q0.9", {"prior": 1.0, "kappa": 0.5,
                                                  "safety_quantile": 0.9}, True),
    ("prior only, kappa 0.5, probe", {"prior": 1e6, "kappa": 0.5}, True),
    ("k2 idw, pt1 norm, probe", {"norm": "pt1"}, True),
    ("k2 idw + prior 1, kappa 0.5, pt1 norm, probe", {"prior": 1.0, "kappa": 0.5, "norm": "pt1"},
     True),
    ("all gauss h2 + prior 1, kappa 0.5, pt1 norm, probe", {"k": 0, "kernel": "gauss",
     "bandwidth": 2.0, "prior": 1.0, "kappa": 0.5, "norm": "pt1"}, True),
    ("k2 idw + prior 1, base norm, probe", {"prior": 1.0, "norm": "base"}, True),
    ("k2 idw + prior 1, probe, hybrid q0.9", {"prior": 1.0, "hybrid_quantile": 0.9}, True),
    ("k2 idw + prior 1, probe, hybrid q0.95", {"prior": 1.0, "hybrid_quantile": 0.95}, True),
    ("k2 idw + prior 1, kappa 0.5, pt1 norm, probe, hybrid q0.9", {"prior": 1.0, "kappa": 0.5,
     "norm": "pt1", "hybrid_quantile": 0.9}, True),
    ("k3 idw + prior 1, kappa 1, pt1 norm, probe", {"k": 3, "prior": 1.0, "kappa": 1.0,
     "norm": "pt1"}, True),
    # A probe of the hybrid frame too (simulated from the scene's hard + none row; the renderer
    # does not run it): hybrid rows scaled by it, the path tracer's and hybrid+pt's by pt 1 spp.
    ("k2 idw + prior 1, hybrid probe", {"prior": 1.0}, "hybrid"),
    ("k2 idw + prior 1, hybrid probe, hybrid q0.95", {"prior": 1.0, "hybrid_quantile": 0.95},
     "hybrid"),
]


def row(cells, budgets, role):
    out = []
    for b in budgets:
        m = ft.summary(cells, b, role)
        out.append("%.2f/%.2f %d %d %d" % (m["median_regret"], min(m["worst_regret"], 99),
                                           m["within_1_1_pt"], m["within_budget"], m["beats_pt"]))
    return out


def main():
    a = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    a.add_argument("rows")
    a.add_argument("--fit", required=True)
    a.add_argument("--budgets", default="50,100,250,500,1000")
    a.add_argument("--pt-margin", type=float, default=0.9)
    a.add_argument("--drift", default="build/release/bin/drift")
    a.add_argument("--only", help="the variants whose names contain this")
    a.add_argument("--guided", choices=("off", "all", "direct"), default="off")
    a.add_argument("--guided-margin", type=float,
                   help="every variant's margin for the hybrid+pt rows (default: --pt-margin's)")
    a.add_argument("--baseline", help="rows the shipped model was fitted on")
    a.add_argument("--baseline-prior", type=float, default=1.0)
    a.add_argument("--baseline-guided", choices=("off", "all", "direct"), default="off",
                   help="the baseline's hybrid+pt candidates (its rows must hold them: "
                        "merge_rows.py); with --guided-margin, at that margin")
    a.add_argument("--baseline-norm", choices=("best", "pt1", "base"), default="best")
    a.add_argument("--probe-safety", type=float,
                   help="with the probe, every variant's (and the baseline's) safety this factor "
                        "for both groups, as drift render applies the model's calibrated_safety, "
                        "in place of the fitted residuals' quantile")
    o = a.parse_args()
    budgets = [float(b) for b in o.budgets.split(",")]
    scenes = ft.load(o.rows, o.drift)
    fit_set = {os.path.realpath(l.strip()) for l in open(o.fit) if l.strip() and not l.startswith("#")}
    names = {os.path.basename(p).rsplit(".", 1)[0] for p in fit_set}
    is_fit = lambda s: os.path.realpath(s["path"]) in fit_set or s["name"] in names
    fit_scenes = [s for s in scenes if is_fit(s)]
    judge = [s for s in scenes if not is_fit(s)]
    print("%s: %d fit scenes, %d judge scenes, --guided %s; cell = median/worst regret, cells "
          "<= 1.1x best pt, cells within budget, cells within budget beating the best pt and "
          "pt+denoise (of %d)\n" % (
              os.path.basename(o.rows), len(fit_scenes), len(judge), o.guided, len(judge)))
    head = " | ".join("%g ms" % b for b in budgets)
    print("| variant | selection score (fit LOSO) | fit: median eff. regret | "
          "judge score (reported, not used to choose) | train | " + head + " |")
    print("|---|---|---|---|---|" + "---|" * len(budgets))
    if o.baseline:
        ft.set_guided(o.baseline_guided)
        base = [s for s in ft.load(o.baseline, o.drift) if is_fit(s)]
        model = ft.fit(base, {"prior": o.baseline_prior, "probe_safety": o.probe_safety,
                              "norm": o.baseline_norm, "guided_margin": o.guided_margin})
        cells = [c for s in judge
                 for c in ft.scene_cells(model, s, False, budgets, o.pt_margin, True)]
        print("| baseline: fitted on %s (%d fit scenes), prior %g, probe, guided %s, norm %s "
              "| | | %.4f | fit | %s |" % (
            os.path.basename(o.baseline), len(base), o.baseline_prior, o.baseline_guided,
            o.baseline_norm, score(cells),
            " | ".join(row(cells, budgets, "judge"))))
    ft.set_guided(o.guided)
    for name, qp, probe in VARIANTS:
        if o.only and o.only not in name:
            continue
        qp = dict(qp, probe_safety=o.probe_safety, guided_margin=o.guided_margin)
        sel = ft.loso(fit_scenes, is_fit, budgets, o.pt_margin, False, qp, probe)
        sc = score(sel)
        med = ft.median([effective(c) for c in sel])
        for train_all in (False, True):
            # The judge scenes' cells: a judge scene is never in its own model.
            cells = [c for c in ft.loso(scenes if train_all else fit_scenes + judge, is_fit, budgets,
                                        o.pt_margin, train_all, qp, probe) if not c["fit"]]
            print("| %s | %s | %s | %.4f | %s | %s |" % (
                name if not train_all else "", "%.4f" % sc if not train_all else "",
                "%.2f" % med if not train_all else "", score(cells), "all" if train_all else "fit",
                " | ".join(row(cells, budgets, "judge"))))
        sys.stdout.flush()


if __name__ == "__main__":
    sys.exit(main())
