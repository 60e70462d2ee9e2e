#!/usr/bin/env bash
# Issue 40, item 6: the seeds' claims measured over the corpus (scenes/corpus/README.md).
#   SIR:  speed-up at equal image (PRT ms / SIR ms to FLIP <= 0.01 of the pure image) >= 3x on
#         the corpus's glossy scenes;
#   AAF:  shadows at 4 spp >= 1.5x plain MC's equal-error sample ratio on every area-lit scene.
# One table per claim, a row per scene and binary; every binary runs a scene back to back
# (a before/after pair is one run). The fit scenes may be tuned on; the judge scenes count.
#
#   bench/experiments/corpus-claims.sh [--quick] [--aaf-only | --sir-only] [--aaf-ref plain]
#       [--aaf-scenes "NAME ..."] [--sir-scenes "NAME ..."] [--aaf-size WxH] [DRIFT ...]
#
# DRIFT: drift binaries (default build/release/bin/drift). --quick leaves out the corpus's
# large scenes (the Breakfast Room). --aaf-ref plain: AAF's reference is plain MC's own
# estimate at --ref-spp instead of the path-traced direct light (where the hybrid's unshadowed
# light differs from the path tracer's, that difference is an error floor no shadow sampler
# moves; `drift bench aaf --ref`). --aaf-size: AAF's error images (default 160x120; the
# issue's targets are at 400x400, where a 1024-spp reference takes minutes a scene). The
# Blender scenes are built into $CORPUS (default build/corpus) by scripts/corpus/build.sh
# when missing. Raw output goes to $OUT
# (default /tmp/corpus-claims).
set -euo pipefail
root="$(cd "$(dirname "$0")/../.." && pwd)"
cd "$root"
quick=0 aaf=1 sir=1 aaf_ref=path aaf_w=160 aaf_h=120
# The claims' scenes, chosen from the manifest's "stresses" lines: every scene lit by an area
# light (quads, spheres, emissive meshes; not suns, points, spots or panoramas alone) for AAF,
# every scene whose look is its glossy or metal surfaces for SIR.
AAF_SCENES="cornell-box breakfast-room plants-blinds cornell-glossy cornell-bunny veach-mi bl-room-area bl-emissive"
SIR_SCENES="cornell-glossy bl-metals veach-mi teapot-studio"
bins=()
while [ $# -gt 0 ]; do
    case "$1" in
    --quick) quick=1 ;;
    --aaf-only) sir=0 ;;
    --sir-only) aaf=0 ;;
    --aaf-ref) aaf_ref="$2"; shift ;;
    --aaf-scenes) AAF_SCENES="$2"; shift ;;
    --sir-scenes) SIR_SCENES="$2"; shift ;;
    --aaf-size) aaf_w="${2%x*}" aaf_h="${2#*x}"; shift ;;
    -h | --help) sed -n '2,/^set /{/^#/p}' "$0"; exit 0 ;;
    *) bins+=("$1") ;;
    esac
    shift
done
[ ${#bins[@]} -gt 0 ] || bins=(build/release/bin/drift)
CORPUS=${CORPUS:-$root/build/corpus}
OUT=${OUT:-/tmp/corpus-claims}
mkdir -p "$OUT"

# name -> "role file" from corpus.json (large scenes dropped under --quick).
scene_info() {
    python3 - "$root/scenes/corpus/corpus.json" "$1" "$quick" "$CORPUS" "$root" <<'PY'
import json, sys
manifest, name, quick, corpus, root = sys.argv[1:]
for s in json.load(open(manifest))["scenes"]:
    if s["name"] == name:
        if quick == "1" and s.get("large"):
            sys.exit(0)
        f = s["file"]
        print(s["role"], corpus + "/" + f[1:] if f.startswith("@") else root + "/" + f)
PY
}

need_blender=$(for n in $AAF_SCENES $SIR_SCENES; do case $n in bl-*) echo "$n" ;; esac; done | sort -u)
missing=""
for n in $need_blender; do
    f=$(scene_info "$n" | cut -d' ' -f2)
    [ -z "$f" ] || [ -f "$f" ] || missing="$missing,$n"
done
if [ -n "$missing" ]; then
    scripts/corpus/build.sh --only "${missing#,}" --out "$CORPUS" >&2
fi

AAF_ARGS="--effect shadows --spp 4,8,16 --mc-spp 4,8,16,32,64 --ref-spp 1024 --width $aaf_w --height $aaf_h --timing-size 80x80 --timing-spp 4 --threads 2 --ref $aaf_ref"
SIR_ARGS="--sizes 200x150 --spp 16 --threads 2 --json"

if [ "$aaf" = 1 ]; then
    echo "## AAF shadows: equal-error sample ratio against plain MC (claim: >= 1.5x at 4 spp), reference: $aaf_ref"
    echo
    echo "    drift bench aaf SCENE $AAF_ARGS"
    echo
    echo "| scene | role | binary | 4 spp | 8 spp | 16 spp | AAF RMSE at 4 spp | plain MC RMSE at 4 spp |"
    echo "|---|---|---|---|---|---|---|---|"
    for n in $AAF_SCENES; do
        read -r role file <<<"$(scene_info "$n")" || true
        [ -n "${file:-}" ] || continue
        for b in "${bins[@]}"; do
            log="$OUT/aaf-$aaf_ref-${aaf_w}x$aaf_h-$n-$(echo "$b" | tr '/' '_').txt"
            # shellcheck disable=SC2086
            nice "$b" bench aaf "$file" $AAF_ARGS >"$log" 2>&1 || { echo "| $n | $role | $b | failed: $log |"; continue; }
            awk -v n="$n" -v role="$role" -v b="$b" '
                $1 == 4 && NF >= 5 && !r4 { r4 = $4; e4 = $3 }
                $1 == 8 && NF >= 5 && !r8 { r8 = $4 }
                $1 == 16 && NF >= 5 && !r16 { r16 = $4 }
                /^plain MC/ { split($0, a, " "); mc4 = a[7] }
                END { printf "| %s | %s | %s | %s | %s | %s | %s | %s |\n", n, role, b, r4, r8, r16, e4, mc4 }' "$log"
        done
    done
    echo
fi

if [ "$sir" = 1 ]; then
    echo "## SIR: PRT ms / SIR ms to the pure image (claim: >= 3x to FLIP <= 0.01)"
    echo
    echo "    drift bench sir SCENE $SIR_ARGS [--components]"
    echo
    echo "| scene | role | binary | refinement | error px % | real error px % | PRT ms | SIR ms to FLIP <= 0.01 | speed-up there | speed-up when done | FLIP done | SIR rays / PRT rays | raster + metrics / PRT | bound |"
    echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
    for n in $SIR_SCENES; do
        read -r role file <<<"$(scene_info "$n")" || true
        [ -n "${file:-}" ] || continue
        for mode in whole components; do
            extra=""
            [ "$mode" = components ] && extra="--components"
            for b in "${bins[@]}"; do
                log="$OUT/sir-$n-$mode-$(echo "$b" | tr '/' '_').json"
                # shellcheck disable=SC2086
                nice "$b" bench sir "$file" $SIR_ARGS $extra >"$log" 2>"$log.err" || { echo "| $n | $role | $b | $mode | failed: $log.err |"; continue; }
                python3 - "$log" "$n" "$role" "$b" "$mode" <<'PY'
import json, sys
path, n, role, b, mode = sys.argv[1:]
for r in json.load(open(path))["rows"]:
    to = r["sir_to_flip_ms"]
    there = "%.2fx" % r["speedup_to_flip"] if to and to > 0 else "not reached"
    # bound: the speed-up of an oracle that traced exactly the real-error pixels (at PRT's
    # cost a pixel) after the raster and the metrics.
    share = (r["raster_ms"] + r["metrics_ms"]) / r["prt_ms"]
    bound = 1.0 / (share + r["real_error_percent"] / 100.0)
    print("| %s | %s | %s | %s | %.1f | %.1f | %.0f | %s | %s | %.2fx | %.4f | %.3f | %.3f | %.2fx |" % (
        n, role, b, mode, r["error_percent"], r["real_error_percent"], r["prt_ms"],
        "%.0f" % to if to and to > 0 else "-", there, r["speedup"], r["flip"],
        r["sir_rays"] / r["prt_rays"], share, bound))
PY
            done
        done
    done
fi
