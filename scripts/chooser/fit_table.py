#!/usr/bin/env python3
"""Fits the technique chooser of `drift render --budget-ms T` (issue 40) from
`drift bench frontier --corpus ... --json`, and validates it leave-one-scene-out.

    python3 scripts/chooser/fit_table.py ROWS.jsonl --fit corpus-fit.txt \\
        [--model scenes/corpus/chooser.json] [--frontier-md docs/frontier.md] \\
        [--drift build/release/bin/drift]

ROWS.jsonl: the bench's --json lines, one a scene (scene, size, features, rows of family,
name, ms, FLIP). Scenes without features get them from `drift render SCENE --features`.

The model (what tools/render_choose.c reads) has two parts, both fitted on the --fit scenes:
- a cost model: each candidate row's predicted milliseconds at the bench's size,
  log ms = alpha_row + beta_group . x(scene), x = COST_FEATURES (triangles, lights,
  environment), one beta for the path tracer's rows and one for the hybrid rows, ridge least
  squares; a frame of P pixels costs P / size^2 of that;
- a quality model: each fitted scene's features and its rows' FLIP over the scene's best;
  a candidate's predicted log FLIP ratio on a new scene is the kernel-weighted mean over the
  k nearest fitted scenes (standardised features), shrunk toward the candidate's prior (its
  mean over every fitted scene) with weight --prior against the neighbours' 1; --kappa > 0
  ranks by that plus kappa x the spread (QUALITY, predict()).
The pick is the candidate with the lowest predicted FLIP whose predicted ms fit T; a hybrid
row is taken only when it is predicted below PT_MARGIN x the best path-tracer candidate,
else the path tracer (plain, a-trous, drift's feature denoiser, or at 1/2 or 1/4 resolution
upsampled bilinearly) is picked and the renderer says so.
With --guided all (or direct) the bench's hybrid+pt rows of the split filter are candidates
too (hybrid group): cost exp(a_guide + beta_hybrid . x) + the pt+denoise row at the same spp
(fit_guided()); off by default (measured worse on the judge scenes: lab log s7-chooser).

Validation (printed): leave-one-scene-out, each scene's pick made by a model fitted on the
--fit scenes without it; per (scene, budget) cell the regret = the chosen row's measured FLIP
over the best row in hindsight within the budget (any row the bench ran), and the chosen
FLIP over the best path tracer's. Fit and judged (unseen) scenes are summarised apart.
"""
import argparse
import json
import math
import os
import re
import subprocess
import sys

FEATURES = ["log_triangles", "log_lights", "area_share", "delta_share", "environment",
            "glossy_share", "emissive_share", "lens", "depth_range", "log_rays"]
# What a frame costs beyond its pixels: triangles (the rays' traversal), lights (shadow maps,
# light samples), the rays a path-tracer sample casts (tools/scene_features.c's probe), an
# environment, a lens. (A timed probe instead of log_rays did no better leave-one-out on the
# corpus rows: docs/lab/2026-12-07-issue-40-s2.md.)
COST_FEATURES = ["log_triangles", "log_lights", "log_rays", "environment", "lens"]
SAFETY_QUANTILE = 0.8
PT_FAMILIES = {"pt", "pt+atrous", "pt+denoise", "pt-low", "pt-low+atrous"}
# What drift render can run: every hybrid row; the path tracer plain, through a-trous or the
# feature denoiser; at reduced resolution upsampled bilinearly (the joint-bilateral rows need
# a full-resolution G-buffer the renderer does not build: in the hindsight best, not picked).
# hybrid+pt (bench/bench_frontier_guided.c): a hybrid frame (the default, "cheap" or "direct"
# guide) plus the path tracer at n spp through drift_denoise_guided; drift render runs its
# `split` filter only (--mode hybrid --denoise guided --spp n), so only those rows can be
# picked, and only with --guided (all: the three guides; direct: the guide without indirect,
# whose one-shot set-up is small). Off by default: over the s7 rows the judge scenes' figures
# got worse with it (docs/lab/2026-12-07-issue-40-s7-chooser.md).
GUIDED = "hybrid+pt"
# The row a hybrid probe would time on the scene at hand (leave-one-out's probe "hybrid": the
# hybrid frame's rows scaled by this row's measured over predicted ms; a simulation, the
# renderer does not run it).
HYBRID_PROBE = ("hybrid", "hard + none")
GUIDED_ROWS = {"all": r"^(cheap |direct )?split (\d+) spp$", "direct": r"^(direct )split (\d+) spp$"}
GUIDED_ROW = re.compile(GUIDED_ROWS["all"])
PICKABLE = {"hybrid"} | PT_FAMILIES
RIDGE = 0.1
# The quality model's and the pick's parameters (model_json writes them, render_choose.c reads
# them): the k nearest scenes (0: all), their kernel ("idw": 1 / (d + 0.1); "gauss":
# exp(-d^2 / 2 bandwidth^2)), the prior's weight against the neighbourhood's, kappa (the pick
# ranks by mean + kappa x spread of the log ratio), robust feature scales, the cost safety's
# quantile. These defaults are session 2's chooser.
QUALITY = {"k": 2, "kernel": "idw", "bandwidth": 1.0, "prior": 0.0, "kappa": 0.0,
           "robust": False, "safety_quantile": SAFETY_QUANTILE, "hybrid_quantile": None,
           "norm": "best", "probe_safety": None, "guided_margin": None}


def key_text(key):
    return "%s|%s" % key


def pickable(key):
    if key[0] == GUIDED:
        return GUIDED in PICKABLE and bool(GUIDED_ROW.match(key[1]))
    return key[0] in PICKABLE and "joint-bilateral" not in key[1]


def set_guided(mode):
    """Which hybrid+pt rows are candidates: "off" (none), "all" (the three guides' split rows)
    or "direct" (the direct guide's); the fit and the pick read PICKABLE and GUIDED_ROW."""
    global GUIDED_ROW
    PICKABLE.discard(GUIDED)
    if mode != "off":
        PICKABLE.add(GUIDED)
    GUIDED_ROW = re.compile(GUIDED_ROWS["all" if mode == "off" else mode])


def guided_parts(key):
    """(guide, the path tracer's row it adds) of a hybrid+pt row: guide "" (the default hybrid
    frame), "cheap " or "direct "; (None, None) for any other row."""
    m = GUIDED_ROW.match(key[1]) if key[0] == GUIDED else None
    return (m.group(1) or "", ("pt+denoise", "%s spp" % m.group(2))) if m else (None, None)


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
        feats = d.get("features") or {}
        if any(k not in feats for k in FEATURES):  # a bench older than a feature
            out = subprocess.run([drift, "render", d["scene"], "--features", "--quiet"],
                                 capture_output=True, text=True, check=True).stdout
            feats = dict(feats, **json.loads(out))
        scenes.append({"size": d.get("size", 400), "path": d["scene"],
                       "name": os.path.basename(d["scene"]).rsplit(".", 1)[0],
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


def group(key):
    return "pt" if key[0] in PT_FAMILIES else "hybrid"


def cost_x(s):
    return [s["features"][FEATURES.index(k)] for k in COST_FEATURES]


def solve(a, b):
    """a x = b by Gaussian elimination with partial pivoting (a small, square)."""
    n = len(b)
    m = [row[:] + [b[i]] for i, row in enumerate(a)]
    for c in range(n):
        p = max(range(c, n), key=lambda r: abs(m[r][c]))
        m[c], m[p] = m[p], m[c]
        for r in range(n):
            if r != c and m[c][c] != 0.0:
                f = m[r][c] / m[c][c]
                m[r] = [x - f * y for x, y in zip(m[r], m[c])]
    return [m[i][n] / m[i][i] if m[i][i] else 0.0 for i in range(n)]


def pt_class(key):
    """A path-tracer row's class (family and what is left of its name without the spp) and
    its spp; (None, 0) for a hybrid row."""
    m = re.match(r"(.*?)(\d+) spp(.*)$", key[1]) if group(key) == "pt" else None
    return ((key[0], m.group(1), m.group(3)), int(m.group(2))) if m else (None, 0)


def smooth_pt(alpha, count):
    """The path tracer's rows of one class (family, resolution, upsampling) cost
    c_class + gamma log spp, gamma shared: one row's time is a single noisy run, the class's
    line pools them (weighted by the rows' scene counts)."""
    cls = {}
    for k, a in alpha.items():
        c, spp = pt_class(k)
        if c is not None:
            cls.setdefault(c, []).append((math.log(spp), a, count[k]))
    if not cls:
        return alpha
    # gamma from the within-class covariance, then each class's intercept
    sxy = sxx = 0.0
    for pts in cls.values():
        w = sum(p[2] for p in pts)
        mx = sum(p[0] * p[2] for p in pts) / w
        my = sum(p[1] * p[2] for p in pts) / w
        sxy += sum(p[2] * (p[0] - mx) * (p[1] - my) for p in pts)
        sxx += sum(p[2] * (p[0] - mx) ** 2 for p in pts)
    gamma = sxy / sxx if sxx > 0 else 1.0
    out = dict(alpha)
    for c, pts in cls.items():
        w = sum(p[2] for p in pts)
        icpt = sum(p[2] * (p[1] - gamma * p[0]) for p in pts) / w
        for k in alpha:
            kc, spp = pt_class(k)
            if kc == c:
                out[k] = icpt + gamma * math.log(spp)
    return out


def fit_cost(train, quantile=SAFETY_QUANTILE, hybrid_quantile=None):
    """alpha per pickable row, beta per group: log ms = alpha + beta . x (block coordinate
    descent on the ridge least squares; it is convex, 50 rounds converge)."""
    every = [(key, cost_x(s), math.log(ms), s["name"]) for s in train
             for key, (ms, f) in s["rows"].items() if pickable(key) and 0.0 < ms < math.inf]
    obs = [o for o in every if o[0][0] != GUIDED]
    d = len(COST_FEATURES)
    beta = {"pt": [0.0] * d, "hybrid": [0.0] * d}
    alpha = {}
    for _ in range(50):
        sums = {}
        for key, x, y, _ in obs:
            r = y - sum(b * v for b, v in zip(beta[group(key)], x))
            t = sums.setdefault(key, [0.0, 0])
            t[0] += r
            t[1] += 1
        alpha = smooth_pt({k: t[0] / t[1] for k, t in sums.items()},
                          {k: t[1] for k, t in sums.items()})
        for g in beta:
            ata = [[RIDGE * (i == j) for j in range(d)] for i in range(d)]
            atb = [0.0] * d
            for key, x, y, _ in obs:
                if group(key) != g:
                    continue
                r = y - alpha[key]
                for i in range(d):
                    atb[i] += x[i] * r
                    for j in range(d):
                        ata[i][j] += x[i] * x[j]
            beta[g] = solve(ata, atb)
    # The safety factor: a pick must fit the budget at its prediction x the SAFETY_QUANTILE of
    # measured over predicted on the training rows (each group), so that most picks fit.
    # probe_safety: the same of the residuals less the scene's "pt 1 spp" residual, what is left
    # once a probe of that row has scaled the scene's predictions (leave-one-out's --probe).
    res = {"pt": [], "hybrid": []}
    probe_res = {"pt": [], "hybrid": []}
    resid = [(key, y - alpha[key] - sum(b * v for b, v in zip(beta[group(key)], x)), name)
             for key, x, y, name in obs]
    pt1 = {name: r for key, r, name in resid if key == ("pt", "1 spp")}
    hy1 = {name: r for key, r, name in resid if key == HYBRID_PROBE}
    hprobe_res = []
    for key, r, name in resid:
        res[group(key)].append(r)
        if name in pt1 and key != ("pt", "1 spp"):
            probe_res[group(key)].append(r - pt1[name])
        if group(key) == "hybrid" and name in hy1 and key != HYBRID_PROBE:
            hprobe_res.append(r - hy1[name])
    qs = {"pt": quantile, "hybrid": hybrid_quantile or quantile}
    q = lambda r, g: math.exp(sorted(r)[int(qs[g] * (len(r) - 1))]) if r else 1.0
    alpha, plus = fit_guided(alpha, beta, [o for o in every if o[0][0] == GUIDED])
    return (alpha, beta, {g: q(r, g) for g, r in res.items()},
            {g: q(r, g) for g, r in probe_res.items()}, plus, q(hprobe_res, "hybrid"))


def fit_guided(alpha, beta, obs):
    """The hybrid+pt rows' cost, as the bench measures them (the guide's warm frame + the path
    tracer's n spp + the filter): exp(a_guide + beta_hybrid . x) + the predicted ms of
    pt+denoise at n spp (its render and a feature-denoiser pass, about the split filter's).
    One a a guide, fitted by least squares on log ms (a 1-D golden-section search: the rest
    of the model is held). The safety factors are the other rows' (these are not in them)."""
    alpha, plus = dict(alpha), {}
    by_guide = {}
    for key, x, y, _ in obs:
        guide, pt = guided_parts(key)
        if pt in alpha:
            plus[key] = pt
            by_guide.setdefault(guide, []).append((key, x, y))
    for guide, pts in by_guide.items():
        pre = [(math.exp(alpha[plus[k]] + sum(b * v for b, v in zip(beta["pt"], x))),
                sum(b * v for b, v in zip(beta["hybrid"], x)), y) for k, x, y in pts]
        err = lambda a: sum((math.log(math.exp(a + h) + p) - y) ** 2 for p, h, y in pre)
        lo, hi = -10.0, 15.0
        for _ in range(80):
            m1, m2 = lo + 0.382 * (hi - lo), lo + 0.618 * (hi - lo)
            lo, hi = (lo, m2) if err(m1) < err(m2) else (m1, hi)
        for k, _, _ in pts:
            alpha[k] = 0.5 * (lo + hi)
    return alpha, plus


def predict_ms(cost, key, x):
    """exp(alpha + beta[group] . x); a hybrid+pt row adds its path tracer's row's (cost[4])."""
    alpha, beta = cost[0], cost[1]
    if key not in alpha:
        return math.inf
    ms = math.exp(alpha[key] + sum(b * v for b, v in zip(beta[group(key)], x)))
    pt = cost[4].get(key) if len(cost) > 4 else None
    return ms + predict_ms(cost, pt, x) if pt else ms


def scales(train, robust=False):
    """Each feature's spread over the training scenes (floor 0.1): the standard deviation, or
    robust: 1.4826 x the median absolute deviation (one outlying scene does not stretch it)."""
    out = []
    for k in range(len(FEATURES)):
        v = [s["features"][k] for s in train]
        if robust:
            m = median(v)
            sd = 1.4826 * median([abs(x - m) for x in v])
        else:
            m = sum(v) / len(v)
            sd = math.sqrt(sum((x - m) ** 2 for x in v) / len(v))
        out.append(max(sd, 0.1))
    return out


def quality(s, norm="best"):
    """The scene's pickable rows' FLIP over its best row's (norm "pt1": over its path tracer's
    at 1 spp, a row every scene has, whereas the best row depends on how far the bench ran;
    "base": over its best row but hybrid+pt's, so that adding those rows to older rows,
    scripts/chooser/merge_rows.py, leaves the older rows' ratios as they were)."""
    best = min(f for k, (_, f) in s["rows"].items() if norm != "base" or k[0] != GUIDED)
    if norm == "pt1" and ("pt", "1 spp") in s["rows"]:
        best = s["rows"][("pt", "1 spp")][1]
    return {k: f / best for k, (ms, f) in s["rows"].items() if pickable(k)}


def ratio_of(q, key):
    """A fitted scene's FLIP ratio of `key`, or of the same row without its environment filter
    (a scene without an environment ran it without); None where the scene has neither."""
    v = q.get(key)
    return v if v is not None else q.get((key[0], re.sub(r" ef \d+", "", key[1])))


_COST = {}


def fit(train, qp=None):
    """The model fitted on `train`: the cost model, the features' scales, each scene's FLIP
    ratios and each candidate's prior (mean and variance of its log ratio over the scenes)."""
    qp = dict(QUALITY, **(qp or {}))
    # Keyed by the scenes' objects (two rows files hold scenes of the same names) and the
    # candidates (--guided).
    memo = (tuple(id(s) for s in train), qp["safety_quantile"], qp["hybrid_quantile"],
            GUIDED in PICKABLE, GUIDED_ROW.pattern)
    if memo not in _COST:  # the same training scenes' cost model (the slow part) once
        _COST[memo] = fit_cost(train, qp["safety_quantile"], qp["hybrid_quantile"])
    cost = _COST[memo]
    if qp.get("probe_safety"):  # the renderer's: calibrated_safety, not the fitted residuals'
        cost = cost[:3] + ({g: qp["probe_safety"] for g in cost[3]},) + cost[4:]
    scenes = [(s["name"], s["features"], quality(s, qp["norm"])) for s in train]
    prior = {}
    for key in cost[0]:
        logs = [math.log(v) for v in (ratio_of(q, key) for _, _, q in scenes) if v]
        if logs:
            m = sum(logs) / len(logs)
            prior[key] = (m, sum((x - m) ** 2 for x in logs) / len(logs))
    return {"cost": cost, "scale": scales(train, qp["robust"]), "scenes": scenes,
            "prior": prior, "q": qp}


def neighbours(model, feats):
    """The K nearest fitted scenes (all with K 0) and their kernel weights, summing to 1."""
    qp, sc = model["q"], model["scale"]
    d = sorted(((math.sqrt(sum(((a - b) / w) ** 2 for a, b, w in zip(f, feats, sc))), q)
                for _, f, q in model["scenes"]), key=lambda t: t[0])
    d = d[:qp["k"]] if qp["k"] > 0 else d
    if qp["kernel"] == "gauss":
        w = [math.exp(-0.5 * (x / qp["bandwidth"]) ** 2) for x, _ in d]
    else:
        w = [1.0 / (x + 0.1) for x, _ in d]
    t = sum(w) or 1.0
    return [(wi / t, q) for wi, (_, q) in zip(w, d)]


def predict(model, near, key):
    """(predicted FLIP ratio, the ratio the pick ranks by) of `key`: the neighbours' weighted
    mean log ratio shrunk toward the candidate's prior (weight `prior` against the
    neighbourhood's 1), and that plus kappa x the spread (the weighted standard deviation of
    the neighbours' and the prior's log ratios about it): a row good on one neighbour and bad
    on another ranks below one good on both."""
    qp = model["q"]
    num = den = 0.0
    pts = []
    for w, q in near:
        v = ratio_of(q, key)
        if v:
            num += w * math.log(v)
            den += w
            pts.append((w, math.log(v)))
    pm = model["prior"].get(key)
    lam = qp["prior"] if pm else 0.0
    if den + lam <= 0.0:
        return math.inf, math.inf
    mean = (num + lam * pm[0]) / (den + lam) if lam else num / den
    var = sum(w * (x - mean) ** 2 for w, x in pts)
    if lam:
        var += lam * (pm[1] + (pm[0] - mean) ** 2)
    var /= den + lam
    return math.exp(mean), math.exp(mean + qp["kappa"] * math.sqrt(var))


def choose(model, feats, budget, pt_margin, cost_scale=None, oracle=None):
    """(key, predicted ms, predicted FLIP ratio, why) for a scene of `feats` at `budget` ms
    (at the model's size); with a probe, every predicted ms times `cost_scale` (what it
    measured) and the safety is the cost model's probe_safety.
    oracle (a diagnosis, not a chooser): the scene's measured rows, their ms in place of the
    predictions (and the safety 1)."""
    x = [feats[FEATURES.index(k)] for k in COST_FEATURES]
    near = neighbours(model, feats)
    cands = []
    for key in model["cost"][0]:
        if oracle is not None:
            ms = lookup(oracle, key)[0]
            fits = ms <= budget
        elif isinstance(cost_scale, dict):  # the hybrid probe too: the hybrid frame's own
            fam = GUIDED if key[0] == GUIDED else group(key)
            ms = predict_ms(model["cost"], key, x) * cost_scale[fam]
            safety = (model["cost"][5] if fam == "hybrid" else model["cost"][3][group(key)])
            fits = ms * safety <= budget
        else:
            ms = predict_ms(model["cost"], key, x) * (cost_scale or 1.0)
            fits = ms * model["cost"][2 if cost_scale is None else 3][group(key)] <= budget
        cands.append((key, ms, predict(model, near, key) if fits else (math.inf, math.inf)))
    fit_ = [c for c in cands if c[2][1] < math.inf]
    if not fit_:
        key, ms, _ = min(cands, key=lambda c: c[1])
        return key, ms, predict(model, near, key)[0], "nothing predicted within the budget: the fastest"
    pt = min((c for c in fit_ if group(c[0]) == "pt"), key=lambda c: c[2][1], default=None)
    # Each hybrid family against the path tracer at its own margin: a hybrid frame must be
    # clearly closer (its risk is a bias the quality model may not see); a hybrid+pt frame is
    # the path tracer's samples plus a guide, its risk is its cost (guided_margin, default
    # pt_margin). The closest of the families that clear their margins.
    gm = model["q"].get("guided_margin") or pt_margin
    clear = []
    for fam, margin in (("hybrid", pt_margin), (GUIDED, gm)):
        hy = min((c for c in fit_ if group(c[0]) == "hybrid"
                  and (c[0][0] == GUIDED) == (fam == GUIDED)), key=lambda c: c[2][1], default=None)
        if hy and (pt is None or hy[2][1] < margin * pt[2][1]):
            clear.append(hy)
    if clear:
        hy = min(clear, key=lambda c: c[2][1])
        return hy[0], hy[1], hy[2][0], "hybrid"
    return pt[0], pt[1], pt[2][0], "path tracer"


def to_pick(key, ms, flip):
    fam, name = key
    if fam == GUIDED:  # drift render --mode hybrid --denoise guided --spp n, the guide's frame
        guide, pt = guided_parts(key)
        p = {"kind": GUIDED, "row": "%s %s" % (fam, name), "spp": int(pt[1].split()[0]),
             "plus": key_text(pt), "shadows": "isg",
             "indirect": "none" if guide == "direct " else "ism"}
        if guide == "cheap ":
            p.update({"vpls": 256, "gather_scale": 2})
        return p
    if group(key) == "pt":
        m = re.match(r"(?:1/(\d+) res )?(\d+) spp", name)
        return {"kind": "pt", "row": "%s %s" % (fam, name), "spp": int(m.group(2)),
                "scale": int(m.group(1) or 1),
                "denoise": {"pt+atrous": "atrous", "pt-low+atrous": "atrous",
                            "pt+denoise": "on"}.get(fam, "none")}
    m = re.match(r"(\w+) \+ (\w+)(.*)$", name)
    p = {"kind": "hybrid", "row": name, "shadows": m.group(1), "indirect": m.group(2)}
    rest = m.group(3)
    for pat, field in ((r" (\d+) VPLs", "vpls"), (r" (\d+) spp", "spp"), (r" ls (\d+)", "light_samples"),
                       (r" ef (\d+)", "environment_filter"), (r" aa (\d+)", "aa")):
        mm = re.search(pat, rest)
        if mm:
            p[field] = int(mm.group(1))
    p["gather_scale"] = 2 if " g2" in rest else 1
    p["no_near_field"] = " nf off" in rest
    p["environment_scale"] = 2 if "environment_filter" in p else 1
    return p


def model_json(model, size, source, pt_margin):
    alpha, beta, safety = model["cost"][:3]
    plus = model["cost"][4] if len(model["cost"]) > 4 else {}
    qp = model["q"]
    cands = []
    for key in sorted(alpha):
        c = to_pick(key, None, None)
        c.update({"key": key_text(key), "alpha": round(alpha[key], 5), "group": group(key)})
        if key in plus:  # its predicted ms adds that candidate's (the path tracer it runs)
            c["plus"] = key_text(plus[key])
        if key in model["prior"]:  # the mean and variance of its log FLIP ratio over the scenes
            c["prior"] = [round(v, 5) for v in model["prior"][key]]
        cands.append(c)
    return {"comment": "The technique chooser of drift render --budget-ms (tools/render_choose.c), "
                       "fitted by scripts/chooser/fit_table.py from %s on the corpus's fit scenes: "
                       "a cost model (log ms at size^2 = alpha + beta[group] . cost features) and, "
                       "for each fitted scene, its features and its rows' FLIP over its best "
                       "(quality.norm: best, its best row's; pt1, its pt 1 spp's); each "
                       "candidate's prior (mean, variance of its log ratio over the scenes)." % source,
            "size": size, "k": qp["k"], "pt_margin": pt_margin, "features": FEATURES,
            "quality": {k: qp[k] for k in ("kernel", "bandwidth", "prior", "kappa", "norm")},
            **({"guided_margin": qp["guided_margin"]} if qp.get("guided_margin") else {}),
            "cost_features": COST_FEATURES, "beta": {g: [round(v, 5) for v in b] for g, b in beta.items()},
            "safety": {g: round(v, 4) for g, v in safety.items()},
            "scale": model["scale"], "candidates": cands,
            "scenes": [{"name": n, "features": f, "flip": {key_text(k): round(v, 4) for k, v in sorted(q.items())}}
                       for n, f, q in model["scenes"]]}


def from_json(m):
    """The model as fit() returns it, from what model_json() wrote (for scripts/chooser/pick.py:
    the script's pick from the file the renderer reads)."""
    key = lambda text: tuple(text.split("|", 1))
    cands = m["candidates"]
    safety = m["safety"]
    return {"cost": ({key(c["key"]): c["alpha"] for c in cands}, m["beta"], safety, safety,
                     {key(c["key"]): key(c["plus"]) for c in cands if "plus" in c}),
            "scale": m["scale"],
            "scenes": [(s["name"], s["features"], {key(k): v for k, v in s["flip"].items()})
                       for s in m["scenes"]],
            "prior": {key(c["key"]): tuple(c["prior"]) for c in cands if "prior" in c},
            "q": dict(QUALITY, k=m.get("k", 2), guided_margin=m.get("guided_margin"),
                      **m.get("quality", {}))}


def median(v):
    v = sorted(v)
    return (v[len(v) // 2] + v[(len(v) - 1) // 2]) / 2 if v else float("nan")


def gmean(v):
    v = [x for x in v if 0 < x < math.inf]
    return math.exp(sum(math.log(x) for x in v) / len(v)) if v else float("nan")


def probe_scale(model, s):
    """What --budget-probe on measures, from the scene's own rows: its path tracer at 1 spp
    over the model's prediction of it (every candidate's predicted ms is scaled by that)."""
    ms, _ = lookup(s["rows"], ("pt", "1 spp"))
    pred = predict_ms(model["cost"], ("pt", "1 spp"), cost_x(s))
    return ms / pred if 0.0 < ms < math.inf and 0.0 < pred < math.inf else 1.0


def loso(scenes, is_fit, budgets, pt_margin, train_all, qp=None, probe=False):
    """The leave-one-scene-out cells: each scene's pick at each budget by a model fitted
    without it (on every other scene, or on the other fit scenes)."""
    cells = []
    for s in scenes:
        train = [t for t in scenes if t is not s and (train_all or is_fit(t))]
        cells += scene_cells(fit(train, qp), s, is_fit(s), budgets, pt_margin, probe)
    return cells


def scene_cells(model, s, role_fit, budgets, pt_margin, probe=False):
    """One scene's cells, each budget's pick by `model` scored on the scene's measured rows."""
    cells = []
    scale = probe_scale(model, s) if probe in (True, "hybrid") else None
    if probe == "hybrid":
        ms, _ = lookup(s["rows"], HYBRID_PROBE)
        pred = predict_ms(model["cost"], HYBRID_PROBE, cost_x(s))
        hy = ms / pred if 0.0 < ms < math.inf and 0.0 < pred < math.inf else scale
        scale = {"pt": scale, GUIDED: scale, "hybrid": hy}
    oracle = s["rows"] if probe == "oracle" else None
    for b in budgets:
        key, pms, _, why = choose(model, s["features"], b, pt_margin, scale, oracle)
        ms, f = lookup(s["rows"], key)
        top, topkey = best_within(s["rows"], b)
        pt, _ = best_within(s["rows"], b, PT_FAMILIES)
        plain, _ = best_within(s["rows"], b, {"pt"})
        den, _ = best_within(s["rows"], b, {"pt+denoise"})
        cells.append({"scene": s["name"], "fit": role_fit, "budget": b, "key": key, "why": why,
                      "pred_ms": pms, "ms": ms, "flip": f, "best": top, "best_key": topkey,
                      "best_pt": pt,
                      # within the budget (measured) and closer than the best plain path
                      # tracer and the best pt+denoise within it (where none fits: beaten)
                      "beats_pt": ms <= b and f < (plain or math.inf) and f < (den or math.inf),
                      "regret": f / top if top and f < math.inf else math.inf,
                      "vs_pt": f / pt if pt and f < math.inf else math.inf})
    return cells


def summary(cells, b, role):
    """One budget's figures over one role's cells (None without cells)."""
    cs = [c for c in cells if c["budget"] == b and c["fit"] == (role == "fit")]
    if not cs:
        return None
    return {"cells": len(cs), "median_regret": median([c["regret"] for c in cs]),
            "worst_regret": max(c["regret"] for c in cs),
            "median_vs_pt": median([c["vs_pt"] for c in cs]),
            "within_1_1_pt": sum(c["vs_pt"] <= 1.1 for c in cs),
            "within_budget": sum(c["ms"] <= b for c in cs),
            "hybrid": sum(group(c["key"]) == "hybrid" for c in cs),
            "guided": sum(c["key"][0] == GUIDED for c in cs),
            "beats_pt": sum(c["beats_pt"] for c in cs),
            "median_flip": median([c["flip"] for c in cs])}


def validate(scenes, is_fit, budgets, pt_margin, out, train_all, qp=None, probe=False):
    cells = loso(scenes, is_fit, budgets, pt_margin, train_all, qp, probe)
    w = out.write
    w("| scene | role | " + " | ".join("%g ms" % b for b in budgets) + " |\n")
    w("|---|---|" + "---|" * len(budgets) + "\n")
    for s in scenes:
        row = []
        for b in budgets:
            c = next(c for c in cells if c["scene"] == s["name"] and c["budget"] == b)
            if c["ms"] == math.inf:  # the bench stopped below it: over the budget there
                row.append("%s %s: not run on this scene (over)" % c["key"])
                continue
            row.append("%s %s: %.3f (%.0f ms%s), regret %.2f, /pt %.2f" % (
                c["key"][0], c["key"][1], c["flip"], c["ms"], "" if c["ms"] <= b else ", over",
                c["regret"], c["vs_pt"]))
        w("| %s | %s | %s |\n" % (s["name"], "fit" if is_fit(s) else "judge", " | ".join(row)))
    w("\n| budget | scenes | cells | median regret | worst regret | median chosen/best pt | "
      "cells <= 1.1x best pt | within budget (measured) | hybrid picked (of which hybrid+pt) | "
      "beats pt and pt+denoise | median chosen FLIP |\n")
    w("|---|---|---|---|---|---|---|---|---|---|---|\n")
    for role in ("judge", "fit"):
        for b in budgets:
            m = summary(cells, b, role)
            if m:
                w("| %g | %s | %d | %.2f | %.2f | %.2f | %d | %d | %d (%d) | %d | %.3f |\n" % (
                    b, role, m["cells"], m["median_regret"], m["worst_regret"], m["median_vs_pt"],
                    m["within_1_1_pt"], m["within_budget"], m["hybrid"], m["guided"],
                    m["beats_pt"], m["median_flip"]))
    return cells


def replace_block(path, text):
    begin, end = "<!-- chooser-loso:begin (scripts/chooser/fit_table.py --frontier-md) -->", \
                 "<!-- chooser-loso:end -->"
    doc = open(path).read() if os.path.exists(path) else ""
    block = begin + "\n" + text + end
    if begin in doc and end in doc:
        doc = doc[:doc.index(begin)] + block + doc[doc.index(end) + len(end):]
    else:
        doc = (doc.rstrip("\n") + "\n\n## The chooser over the corpus, leave-one-scene-out\n\n" +
               block + "\n")
    open(path, "w").write(doc)


def main():
    a = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    a.add_argument("rows")
    a.add_argument("--fit", required=True, help="the fit scenes' list (build/corpus/corpus-fit.txt)")
    a.add_argument("--budgets", default="50,100,250,500,1000")
    a.add_argument("--model", help="write the model fitted on every fit scene here")
    a.add_argument("--frontier-md", help="replace the generated leave-one-out block of this file")
    a.add_argument("--drift", default="build/release/bin/drift")
    a.add_argument("--guided", choices=("off", "all", "direct"), default="off",
                   help="the hybrid+pt split rows pickable: off (the default), all three guides, "
                        "or the direct guide's")
    a.add_argument("--pt-margin", type=float, default=0.9,
                   help="a hybrid row is picked only when predicted below this x the best path "
                        "tracer's FLIP (default 0.9)")
    a.add_argument("--guided-margin", type=float,
                   help="the same for a hybrid+pt row (default: --pt-margin's)")
    q = a.add_argument_group("the quality model and the pick (defaults: session 2's chooser)")
    q.add_argument("--k", type=int, default=QUALITY["k"], help="nearest scenes (0: all)")
    q.add_argument("--kernel", choices=("idw", "gauss"), default=QUALITY["kernel"])
    q.add_argument("--bandwidth", type=float, default=QUALITY["bandwidth"])
    q.add_argument("--prior", type=float, default=QUALITY["prior"],
                   help="the candidate's prior's weight against the neighbourhood's 1")
    q.add_argument("--kappa", type=float, default=QUALITY["kappa"],
                   help="rank by mean + kappa x spread of the predicted log FLIP ratio")
    q.add_argument("--robust", action="store_true", help="features scaled by their MAD")
    q.add_argument("--norm", choices=("best", "pt1", "base"), default=QUALITY["norm"])
    q.add_argument("--safety-quantile", type=float, default=QUALITY["safety_quantile"])
    q.add_argument("--hybrid-quantile", type=float,
                   help="the hybrid rows' safety quantile (default: --safety-quantile's)")
    q.add_argument("--probe", action="store_true",
                   help="leave-one-out as --budget-probe on: each scene's predicted ms scaled "
                        "by its own pt 1 spp row over the prediction of it")
    a.add_argument("--train", choices=("all", "fit"), default="fit",
                   help="what a left-out scene's model is fitted on: the fit scenes (fit, the "
                        "default: a judge scene's pick is the shipped model's) or every other "
                        "scene (all); --model is fitted likewise")
    o = a.parse_args()
    set_guided(o.guided)
    budgets = [float(b) for b in o.budgets.split(",")]
    scenes = load(o.rows, o.drift)
    fit_set = {os.path.realpath(l.strip()) for l in open(o.fit) if l.strip() and not l.startswith("#")}
    fit_names = {os.path.basename(p).rsplit(".", 1)[0] for p in fit_set}
    is_fit = lambda s: os.path.realpath(s["path"]) in fit_set or s["name"] in fit_names

    class Tee:
        def __init__(self):
            self.parts = []

        def write(self, t):
            sys.stdout.write(t)
            self.parts.append(t)

    qp = {"k": o.k, "kernel": o.kernel, "bandwidth": o.bandwidth, "prior": o.prior,
          "kappa": o.kappa, "robust": o.robust, "norm": o.norm,
          "safety_quantile": o.safety_quantile, "hybrid_quantile": o.hybrid_quantile,
          "guided_margin": o.guided_margin}
    tee = Tee()
    validate(scenes, is_fit, budgets, o.pt_margin, tee, o.train == "all", qp, o.probe)
    if o.frontier_md:
        args = " ".join(sys.argv[2:])
        args = re.sub(r"--(model|frontier-md|drift) \S+ ?", "", args).strip()
        head = ("Generated by `python3 scripts/chooser/fit_table.py %s %s` "
                "(leave-one-scene-out: each scene's pick by a model fitted without it, on %s; "
                "%sregret = chosen FLIP / best FLIP in hindsight within the budget; "
                "/pt = chosen FLIP / best path tracer's; %d px, the bench's size).\n\n" % (
                    os.path.basename(o.rows), args,
                    "every other scene" if o.train == "all" else
                    "the fit scenes (a fit scene's on the other fit scenes)",
                    "costs scaled by the scene's own pt 1 spp row, as --budget-probe on scales "
                    "them by its probe; " if o.probe else "", scenes[0]["size"]))
        replace_block(o.frontier_md, head + "".join(tee.parts))
    if o.model:
        train = [s for s in scenes if o.train == "all" or is_fit(s)]
        m = model_json(fit(train, qp), train[0]["size"], os.path.basename(o.rows), o.pt_margin)
        # What --budget-probe on reads that this fit does not make (scripts/chooser/
        # measure_setup.py's set-up table, the safety under calibration) is kept.
        if os.path.exists(o.model):
            old = json.load(open(o.model))
            m.update({k: old[k] for k in ("setup_ms", "calibrated_safety", "finish_ms") if k in old})
        with open(o.model, "w") as fh:
            json.dump(m, fh, indent=1)
            fh.write("\n")


if __name__ == "__main__":
    sys.exit(main())
