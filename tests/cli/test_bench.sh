#!/usr/bin/env bash
# Smoke test of every `drift bench` subcommand: each runs at a tiny size on the built-in
# Cornell box and must exit 0 with sane JSON, answer --help, and reject an unknown option
# with exit status 2 and a message naming it. The benchmarks are read from
# `drift bench --help`, so a new one without a case here fails the test. Speed is not checked
# (docs/benchmarks.md has the figures).
# ctest-labels: slow
set -u
drift="$1"
source "$(dirname "$0")/common.sh"
box="$(cd "$(dirname "$0")/../../scenes/cornell-box" && pwd)/cornell_box.json"

# check NAME PYTHON: runs PYTHON with `d`, the JSON on stdout, bound.
check() {
    python3 - "$tmp/out" "$2" <<'PY' || fail "bench $1: unexpected --json output: $(head -c 300 "$tmp/out")"
import json, math, sys
d = json.load(open(sys.argv[1]))
exec(sys.argv[2])
PY
}

smoke() {
    case "$1" in
    rays)
        expect 0 "$drift" bench rays "$box" --width 16 --height 16 --seconds 0.02 --repeats 1 --json
        check rays 'assert d["results_match"] is True and d["primary"]["rays"] == 256, d
for k in ("primary", "shadow", "bounce"): assert d[k]["drift_rays_per_s"] > 0, k'
        ;;
    frame)
        expect 0 "$drift" bench frame "$box" --width 16 --height 12 --frames 1 --json
        check frame 'assert d["width"] == 16 and len(d["configs"]) >= 1, d
for c in d["configs"]: assert c["frame_ms"] > 0 and c["passes"]["primary"] >= 0, c'
        # --floors: each pass against the bytes it must move, at the copy bandwidth of the run.
        expect 0 "$drift" bench frame "$box" --floors --width 16 --height 12 --frames 1 --json
        check frame-floors 'assert d["width"] == 16 and d["copy_gb_per_s"] > 0, d
p = {x["name"]: x for x in d["passes"]}
assert set(p) == {"compose", "post dof", "a-trous", "glare conv", "isg shadows",
                  "isg reflections", "isg dof"}, d
assert p["post dof"]["bytes"] == 16 * 12 * (12 + 4 + 12), p["post dof"]
for x in d["passes"]:
    assert x["ms"] >= 0 and x["floor_ms"] > 0 and x["bytes"] > 0, x
    floor = x["bytes"] / (d["copy_gb_per_s"] * 1e6)  # bytes at the measured bandwidth
    assert abs(x["floor_ms"] - floor) <= 0.01 * floor + 1e-6 and x["floor_ratio"] >= 0, x
assert p["isg dof"]["samples"] == 0 and p["isg shadows"]["samples"] > 0, d  # a pinhole: no DOF
a = p["a-trous"]  # 5 passes apart: colour in and out, albedo, normal (12 bytes), depth (4)
assert a["level_bytes"] == 5 * 16 * 12 * (12 + 12 + 12 + 12 + 4), a
taps = sum(sum(max(0, 16 - abs(t) * 2**i) for t in range(-2, 3)) *
           sum(max(0, 12 - abs(t) * 2**i) for t in range(-2, 3)) - 16 * 12 for i in range(5))
assert a["samples"] == taps and a["compute_floor_ms"] > 0, (a, taps)
assert d["gflop_per_s"] > 0, d
g = p["glare conv"]  # 16 + 128 and 12 + 128 padded to 144 (2^4 3^2): 3 x (2 FFTs + product)
P = 144 * 144
assert abs(g["flops"] - 3 * (2 * 2.5 * P * math.log2(P) + 6 * 73 * 144)) < 1, g
assert abs(g["compute_floor_ms"] - g["flops"] / (d["gflop_per_s"] * 1e6)) <= 1e-3, (g, d)'
        # --passes: only the passes named.
        expect 0 "$drift" bench frame "$box" --floors --width 16 --height 12 --frames 1 --json \
            --passes "post dof,glare conv"
        check frame-floors-passes 'assert [x["name"] for x in d["passes"]] == ["post dof", "glare conv"], d'
        ;;
    isg)
        expect 0 "$drift" bench isg "$box" --width 16 --height 12 --qwidth 16 --qheight 12 \
            --ref-spp 2 --json
        check isg 'assert set(d["effects"]) == {"shadows", "reflections", "dof"}, d
for e in d["effects"].values():
    assert len(e["isg_ms"]) == 4 and all(len(r["search_ms"]) == 4 for r in e["isg_ms"]), e
    assert e["quality"] and all(0 <= q["flip"] <= 1 and q["rmse"] >= 0 for q in e["quality"]), e'
        ;;
    aaf)
        expect 0 "$drift" bench aaf "$box" --width 16 --height 12 --ref-spp 8 --spp 1,2 \
            --timing-size 16x12 --timing-spp 1 --light-samples 2 --json
        check aaf 'assert [e["effect"] for e in d["effects"]] == ["shadows"], d
e = d["effects"][0]
assert len(e["aaf"]) == 2 and len(e["plain_mc"]) == 2, e
assert all(math.isfinite(p["rmse"]) and p["rmse"] >= 0 for p in e["aaf"] + e["plain_mc"]), e
assert e["timing"]["frame_ms"] > 0, e'
        # --ref plain: the reference is plain MC's own estimate, so plain MC at --ref-spp is it.
        expect 0 "$drift" bench aaf "$box" --width 16 --height 12 --ref-spp 4 --ref plain \
            --spp 1,2 --mc-spp 2,4 --timing-size 16x12 --timing-spp 1 --light-samples 2 --json
        check aaf 'assert d["reference"] == "plain", d
e = d["effects"][0]
assert e["plain_mc"][1]["rmse"] == 0 and e["plain_mc"][0]["rmse"] > 0, e'
        # --aaf-filter off: AAF's rows are its samples alone (the filter acts on the box's
        # penumbrae, so their error changes); plain MC's rows are the same.
        cp "$tmp/out" "$tmp/aaf-on.json"
        expect 0 "$drift" bench aaf "$box" --width 16 --height 12 --ref-spp 4 --ref plain \
            --spp 1,2 --mc-spp 2,4 --timing-size 16x12 --timing-spp 1 --light-samples 2 --json \
            --aaf-filter off
        check aaf 'import os
on = json.load(open(os.path.join(os.path.dirname(sys.argv[1]), "aaf-on.json")))
assert d["aaf_filter"] is False and on["aaf_filter"] is True, d
e, f = d["effects"][0], on["effects"][0]
assert [p["rmse"] for p in e["plain_mc"]] == [p["rmse"] for p in f["plain_mc"]], (e, f)
assert [p["rmse"] for p in e["aaf"]] != [p["rmse"] for p in f["aaf"]], (e, f)'
        ;;
    sir)
        expect 0 "$drift" bench sir "$box" --sizes 16x12 --spp 1 --budget 64 --json
        check sir 'r = d["rows"]
assert len(r) == 1 and r[0]["width"] == 16 and r[0]["height"] == 12, d
assert 0 <= r[0]["flip"] <= 1 and r[0]["prt_ms"] > 0 and "shadow" in r[0]["quality"], r
assert "leak" in r[0]["quality"] and r[0]["raster_metrics_time_share"] > 0, r
assert 0 < r[0]["raster_metrics_ray_share"] and r[0]["metrics_rays"] >= 0, r'
        expect 0 "$drift" bench sir "$box" --sizes 16x12 --spp 1 --budget 64 --paper-metrics --json
        check sir 'assert d["rows"][0]["quality"]["leak"]["flagged"] == 0, d'
        expect 0 "$drift" bench sir "$box" --sizes 16x12 --spp 1 --budget 64 --components --json
        check sir 'assert 0 <= d["rows"][0]["flip"] <= 1 and d["rows"][0]["sir_rays"] >= 0, d'
        expect 0 "$drift" bench sir "$box" --sizes 16x12 --spp 1 --budget 64 --envmap-parallax none --json
        check sir 'assert 0 <= d["rows"][0]["flip"] <= 1, d'
        expect 2 "$drift" bench sir "$box" --sizes 16x12 --envmap-parallax sphere
        expect 2 "$drift" render "$box" --mode hybrid --reflections envmap --envmap-parallax sphere
        ;;
    glare)
        expect 0 "$drift" bench glare --frames 1 --sizes 16,32 --no-convolution --json
        check glare 'assert [r["n"] for r in d["sizes"]] == [16, 32], d
assert all(r["overall_ms"] > 0 and r["aperture_ms"] >= 0 for r in d["sizes"]), d'
        ;;
    ssdo)
        # The default scene: the Cornell box has no environment light for SSDO to occlude.
        expect 0 "$drift" bench ssdo --width 8 --height 8 --samples 2 --ref-spp 1 --frames 1 --json
        check ssdo 'assert d["width"] == 8 and d["samples"] == 2 and d["threads"] == 1, d
q = {r["name"]: r for r in d["quality"]}
assert {"ssao", "gtao", "ssdo", "ssdo+bounce", "pt-1spp"} <= set(q), d
assert all(r["ms"] >= 0 and 0 <= r["flip"] <= 1 and r["rmse"] >= 0 and 0 <= r["flip_direct"] <= 1
           for r in d["quality"]), d
assert "table" not in d and d["radius"] > 0, d'
        ;;
    ism)
        expect 0 "$drift" bench ism "$box" --size 16 --height 12 --ref-spp 2 --vpls 8 --spp 1 \
            --points 64 --map 8 --threads 1 --classic --json
        check ism 'assert d["size"] == 16 and d["height"] == 12 and d["ref_spp"] == 2 and d["gbuffer_ms"] >= 0, d
assert [(r["what"], r["count"]) for r in d["rows"]] == [("ref", 2), ("pt", 1), ("ism", 8), ("sm", 8), ("ir", 8)], d
assert all(r["ms"] >= 0 and r["rmse_indirect"] >= 0 and 0 <= r["flip_frame"] <= 1 for r in d["rows"]), d
assert d["rows"][3]["ms"] > 0 and d["rows"][3]["flip_frame"] == d["rows"][2]["flip_frame"], d
assert d["rows"][4]["nrmse_ism_vs_ir"] >= 0 and "nrmse_ism_vs_ir" not in d["rows"][2], d
for r in (d["rows"][2], d["rows"][4]):
    assert 0 < r["vpls"] <= 8 and 0 <= r["holes"] <= 1 and r["stage_ms"]["gather"] >= 0, r'
        expect 2 "$drift" bench ism --vpls 8,,16
        grep -q -- "--vpls expects .*got '8,,16'" "$tmp/err" || fail "bench ism: bad --vpls not named"
        ;;
    micro)
        expect 0 "$drift" bench micro "$box" --size 12 --ref-spp 2 --points 256 --sizes 4,8 \
            --densities 1,16 --scaling 8,9 --csv "$tmp/micro.csv" --json
        check micro 'assert d["size"] == 12 and d["ref_spp"] == 2 and d["threads"] == 1, d
assert [(r["sweep"], r["k"], r["density"], r["points"]) for r in d["rows"]] == [
    ("size", 4, 1, 256), ("size", 8, 1, 256), ("density", 16, 1, 256), ("density", 16, 16, 256),
    ("points", 16, 16, 256), ("points", 16, 16, 512)], d
assert all(r["ms"] >= 0 and r["gathers"] > 0 and r["nodes_visited"] > 0 and r["nrms"] >= 0 and
           set(r["stage_ms"]) == {"hierarchy", "lighting", "gather", "upsample"} for r in d["rows"]), d'
        [ "$(wc -l < "$tmp/micro.csv")" -eq 3 ] || fail "bench micro: --csv should hold 2 rows"
        expect 2 "$drift" bench micro --densities 3
        grep -q -- "--densities expects 1, 4 or 16" "$tmp/err" || fail "bench micro: bad --densities not named"
        ;;
    micro-bounces)
        expect 0 "$drift" bench micro-bounces "$box" --size 8 --ref-spp 2 --points 256 \
            --micro-size 4 --photons 256 --bounces 1,2 --json
        check micro-bounces 'assert d["size"] == 8 and d["points"] == 256, d
assert [(r["reference_bounces"], r["lighting"], r["bounces"]) for r in d["rows"]] == [
    (1, "direct", 1), (2, "direct", 1), (2, "radiosity", 2), (2, "photons", 2)], d
assert all(r["ms"] >= 0 and r["nrms"] >= 0 and 0 <= r["flip"] <= 1 and r["bounces_ms"] >= 0
           for r in d["rows"]), d
assert d["rows"][3]["photons"] > 0 and d["rows"][2]["photons"] == 0, d'
        expect 2 "$drift" bench micro-bounces --bounces 0
        grep -q -- "--bounces expects" "$tmp/err" || fail "bench micro-bounces: bad --bounces not named"
        ;;
    frontier)
        # Twice: the second run must reuse the cached reference and give the same FLIP values.
        # It sweeps a subset (one --aa, one --light-samples, no half-rate gathers: a quarter of
        # the hybrid rows), enough to compare every family's rows with the first run's.
        for run in 1 2; do
            # shellcheck disable=SC2054 # 1,2 and 8,1 are lists of the options
            sweep=(--aa 1,2 --light-samples 8,1 --half-gather-vpls 8
                --csv "$tmp/frontier.csv" --svg "$tmp/frontier.svg")
            [ "$run" = 2 ] && sweep=(--aa 1 --light-samples 1 --half-gather-vpls 0)
            expect 0 "$drift" bench frontier "$box" --size 12 --ref-spp 4 --runs 1 --max-spp 2 \
                --vpls 8 --aaf-spp 1 --sir-iterations 1,2 --budgets 1,20,1000 \
                --cache "$tmp/cache" --threads 1 "${sweep[@]}" --json
            cp "$tmp/out" "$tmp/frontier$run.json"
        done
        check frontier 'second = d
assert second["reference_cached"] is True, second
d = json.load(open(sys.argv[1][:-3] + "frontier1.json"))
assert d["reference_cached"] is False, d
# The same rows give the same FLIP (the reduced-resolution path tracer doubles its spp until
# a time limit, so how many of its rows there are depends on the load of the machine: compare the
# rows both runs have, and every row of the families with a fixed count). The hybrid rows of
# the second run are some of the first run.
flips = lambda run: {(r["family"], r["name"]): r["flip"] for r in run["rows"] if r["family"] != "hybrid"}
f1, f2 = flips(d), flips(second)
assert all(f1[k] == f2[k] for k in f1.keys() & f2.keys()), (f1, f2)
fixed = lambda rows: sorted(k for k in rows if not k[0].startswith("pt-low"))
assert fixed(f1) == fixed(f2), (f1, f2)
hybrid_names = lambda run: {r["name"] for r in run["rows"] if r["family"] == "hybrid"}
assert 6 <= len(hybrid_names(second)) < len(hybrid_names(d)), sorted(hybrid_names(second))
assert hybrid_names(second) <= hybrid_names(d), sorted(hybrid_names(second) - hybrid_names(d))
fam = [r["family"] for r in d["rows"]]
assert fam.count("pt") == 2 and fam.count("pt+atrous") == 2 and fam.count("pt+denoise") == 2 \
    and fam.count("hybrid") >= 20, fam
# Every hybrid combination once more at --aa 2 and at one light sample; SIR rows refine the
# pcss frame.
names = [r["name"] for r in d["rows"] if r["family"] == "hybrid"]
assert sum(n.endswith(" aa 2") for n in names) * 2 == len(names), names
assert sum(" ls 1" in n for n in names) * 2 == len(names), names
assert not any(" ls 8" in n for n in names), names
assert not any(" ef " in n for n in names), names  # no environment, no environment filter rows
# Each ism and ir row of 8 VPLs (under the default --near-field-off-vpls 256) once more without the
# near-field compensation, and (from --half-gather-vpls 8) once more gathering at 2 x 2.
vpl_rows = [n for n in names if " VPLs" in n]
assert vpl_rows and sum(" nf off" in n for n in vpl_rows) * 3 == len(vpl_rows), vpl_rows
assert sum(n.split(" VPLs")[1].startswith(" g2") for n in vpl_rows) * 3 == len(vpl_rows), vpl_rows
assert 1 <= fam.count("sir") <= 2, fam
assert all(r["ms"] > 0 and 0 <= r["flip"] <= 1 and r["rmse"] >= 0 for r in d["rows"]), d
prev = 2.0
for f in d["front"]:
    best = f["best"]
    if best is None:
        continue
    assert best["ms"] <= f["budget_ms"] and best["flip"] <= prev, d["front"]
    prev = best["flip"]
    for k in ("pt", "pt_atrous", "pt_denoise", "hybrid"):
        assert f[k] is None or (f[k]["ms"] <= f["budget_ms"] and f[k]["flip"] >= best["flip"]), f
budgets = [f["budget_ms"] for f in d["front"]]
for r in d["rows"]:
    # The band: the smallest budget over the row ms, above the one before it (null: over all).
    # The JSON rounds ms to 3 decimals: a row of 1.0004 ms reads 1 and is in the 20 ms band.
    band_of = lambda ms: next((x for x in budgets if ms <= x), None)
    band = r["budget_ms"]
    assert band in (band_of(r["ms"] - 1e-3), band_of(r["ms"] + 1e-3)), r
    if band is not None:
        below = [x for x in budgets if x < band]
        assert r["ms"] <= band + 1e-3 and (not below or r["ms"] > below[-1] - 1e-3), r
    # On the front: no row at most as slow is strictly closer (up to the JSON rounding).
    beaten = [q for q in d["rows"] if q is not r and q["ms"] <= r["ms"] + 1e-3 and q["flip"] <= r["flip"] + 1e-6]
    assert (not r["pareto"] or all(q["ms"] > r["ms"] - 1e-3 or q["flip"] >= r["flip"] - 1e-6 for q in beaten)) \
        and (r["pareto"] or beaten), r
# Rows of equal ms (as rounded in the JSON) may both be on the front: the closer one last.
front = sorted((r for r in d["rows"] if r["pareto"]), key=lambda r: (r["ms"], -r["flip"]))
assert front and all(a["flip"] >= b["flip"] for a, b in zip(front, front[1:])), front
for f in d["front"]:
    if f["best"] is not None:
        assert any(r["pareto"] and r["name"] == f["best"]["name"] and r["family"] == f["best"]["family"]
                   for r in d["rows"]), f'
        [ "$(wc -l < "$tmp/frontier.csv")" -ge 15 ] || fail "bench frontier: --csv has too few rows"
        # A scene lit by an environment: every hybrid row once more with --env-filter's passes
        # (and its rays at one pixel in 2 x 2), named "ef 4", a different image.
        expect 0 "$drift" bench frontier "${box%/cornell-box/*}/ssdo-blocks/ssdo_blocks.json" --size 12 \
            --ref-spp 4 --runs 1 --max-spp 1 --vpls 8 --half-gather-vpls 0 --aaf-spp 1 --aa 1 \
            --sir-iterations 1 --budgets 1000 --cache "$tmp/cache" --threads 1 --json
        check frontier 'rows = {r["name"]: r for r in d["rows"] if r["family"] == "hybrid"}
filtered = [n for n in rows if n.endswith(" ef 4")]
assert filtered and len(filtered) * 2 == len(rows), sorted(rows)
assert all(n[:-len(" ef 4")] in rows for n in filtered), sorted(rows)
assert any(rows[n]["flip"] != rows[n[:-len(" ef 4")]]["flip"] for n in filtered), rows'

        python3 -c 'import sys, xml.etree.ElementTree as E; t = E.parse(sys.argv[1]).getroot()
ns = "{http://www.w3.org/2000/svg}"
assert t.tag == ns + "svg" and len(t.findall(ns + "circle")) > 15 and t.findall(ns + "polyline"), t' \
            "$tmp/frontier.svg" || fail "bench frontier: --svg is not a plot of the rows"
        ;;
    redit)
        expect 0 "$drift" bench redit --width 32 --height 24 --constraints 1,4 --frames 1 --json
        check redit 'assert [r["constraints"] for r in d["field"]] == [1, 4], d
assert d["reflective_pixels"] > 0 and all(r["mpixel_per_s"] > 0 for r in d["field"]), d
assert d["frame_ms_unedited"] > 0 and d["frame_ms_edited"] > 0, d'
        ;;
    cycles)
        # Without Blender: skipped with exit status 77 and a message saying so.
        expect 77 "$drift" bench cycles "$box" --blender /nonexistent/blender --size 8 --spp 1
        grep -q "skipped: Blender" "$tmp/err" || fail "bench cycles: missing Blender not said"
        expect 2 "$drift" bench cycles "${box%.json}.obj"
        grep -q "OBJ meshes" "$tmp/err" || fail "bench cycles: a scene Blender cannot read not named"
        if blender --version >/dev/null 2>&1; then
            expect 0 "$drift" bench cycles "$box" --size 16 --spp 4 --ref-spp 64 --max-depth 3 \
                --threads 1 --cache "$tmp/cycles-cache" --out-dir "$tmp/cycles" --json
            check cycles 'assert d["size"] == 16 and d["spp"] == 4 and d["threads"] == 1 and d["fit_spp"] == 1, d
for k in ("drift", "cycles"):
    r = d[k]
    assert r["process_s"] > 0 and r["render_s"] > 0 and r["process_s"] > r["render_s"], r
    assert 0 <= r["flip"] <= 1 and math.isfinite(r["relmse"]) and r["relmse"] > 0, r
for k in ("ratio_process", "ratio_render", "equal_error_ratio", "drift_error_slope", "cycles_error_slope"):
    assert math.isfinite(d[k]) and d[k] > 0, (k, d)
assert 0 < d["reference_relmse"] < d["drift"]["relmse"], d
assert abs(d["ratio_render"] - d["cycles"]["render_s"] / d["drift"]["render_s"]) < 0.05 * d["ratio_render"], d'
            # Another scene JSON of OBJ meshes (the box under another name): obj_cycles.py.
            mkdir -p "$tmp/obj-scene"
            cp "$box" "$tmp/obj-scene/scene.json"
            cp "${box%.json}.obj" "${box%.json}.mtl" "$tmp/obj-scene/"
            expect 0 "$drift" bench cycles "$tmp/obj-scene/scene.json" --size 16 --spp 4 \
                --ref-spp 64 --max-depth 3 --threads 1 --cache "$tmp/cycles-cache" \
                --out-dir "$tmp/cycles-obj" --json
            check cycles 'assert d["scene"].endswith("scene.json") and d["cycles"]["render_s"] > 0, d
assert 0 <= d["cycles"]["flip"] <= 1 and math.isfinite(d["cycles"]["relmse"]), d'
        else
            echo "cli.bench: Blender is not installed: bench cycles checked for its skip only"
        fi
        ;;
    *)
        fail "bench $1 has no smoke case in tests/cli/test_bench.sh"
        return
        ;;
    esac
    expect 0 "$drift" bench "$1" --help
    grep -q "usage: drift bench $1" "$tmp/out" || fail "bench $1 --help prints no usage"
    expect 2 "$drift" bench "$1" --no-such-option
    grep -q -- "--no-such-option" "$tmp/err" || fail "bench $1: unknown option not named"
}

expect 0 "$drift" bench --help
benches=$(sed -n '/^benchmarks:/,/^$/p' "$tmp/out" | awk 'NR > 1 && NF { print $1 }')
[ -n "$benches" ] || fail "drift bench --help lists no benchmarks"
for name in $benches; do
    smoke "$name"
done
expect 2 "$drift" bench no-such-bench
grep -q "no-such-bench" "$tmp/err" || fail "unknown benchmark not named"

if [ "$failures" -ne 0 ]; then
    echo "$failures failure(s)" >&2
    exit 1
fi
echo "cli.bench: every benchmark ran ($(echo $benches))"
