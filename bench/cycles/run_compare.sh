#!/usr/bin/env bash
# drift reference path tracer vs Blender Cycles (CPU), same scene / resolution / depth / spp,
# measured back to back in the same run.
#
#   bench/cycles/run_compare.sh DRIFT_BIN SPP DEPTH
#
# Runs
#   blender -b --factory-startup -noaudio --python bench/cycles/cornell_cycles.py -- \
#       --spp SPP --max-depth DEPTH --threads 1 --width 512 --height 512 --out cycles.exr
#   DRIFT_BIN render --mode reference --spp SPP --max-depth DEPTH --threads 1 \
#       --width 512 --height 512 --out drift.exr --stats drift.json
#   DRIFT_BIN diff cycles.exr drift.exr --json
# and prints the path-tracing time per sample per pixel of both and the ratio drift/cycles.
#
# Environment (all optional):
#   OUT_DIR               where images/logs go            (default /tmp/drift-vs-cycles)
#   WIDTH, HEIGHT         image size                      (default 512 512)
#   THREADS               threads for both renderers      (default 1)
#   REPEATS               alternate Cycles/drift N times, keep the fastest of each (default 1)
#   SEED                  Cycles seed                     (default 0)
#   DRIFT_SCENE           if set, passed to drift render as --scene "$DRIFT_SCENE"
#   DRIFT_ARGS            extra args for drift render (word-split)
#   CYCLES_BOUNCES_OFFSET Cycles max_bounces = DEPTH + offset. Default -1: drift's --max-depth
#                         counts scattering vertices like pbrt (1 = direct light only), Cycles'
#                         max_bounces counts bounces after the first hit (0 = direct light only).
#   CYCLES_ARGS           extra args for cornell_cycles.py. Default
#                         "--rr-min-bounces 1 --one-sided-light --light-diffuse", i.e. as drift's
#                         reference: Russian roulette from the 4th vertex on (rr_depth 3), one-sided
#                         emitter, and the light quad also reflects with its .mtl Kd 0.78.
#                         CYCLES_ARGS=" " = plain Cycles: no roulette, two-sided pure emitter.
#   BLENDER               blender binary                  (default blender)
set -euo pipefail

if [ $# -ne 3 ]; then
    echo "usage: $0 DRIFT_BIN SPP DEPTH" >&2
    exit 2
fi
DRIFT_BIN=$1 SPP=$2 DEPTH=$3
HERE=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
OUT_DIR=${OUT_DIR:-/tmp/drift-vs-cycles}
WIDTH=${WIDTH:-512} HEIGHT=${HEIGHT:-512} THREADS=${THREADS:-1} REPEATS=${REPEATS:-1}
SEED=${SEED:-0} BLENDER=${BLENDER:-blender}
CYCLES_BOUNCES_OFFSET=${CYCLES_BOUNCES_OFFSET:--1}
CYCLES_ARGS=${CYCLES_ARGS:---rr-min-bounces 1 --one-sided-light --light-diffuse}
mkdir -p "$OUT_DIR"

if ! "$BLENDER" --version >/dev/null 2>&1; then
    echo "run_compare: blender not found; run scripts/install-cycles.sh first" >&2
    exit 1
fi
if [ ! -x "$DRIFT_BIN" ] && ! command -v "$DRIFT_BIN" >/dev/null 2>&1; then
    echo "run_compare: drift binary '$DRIFT_BIN' not found / not executable" >&2
    exit 1
fi

CY_EXR=$OUT_DIR/cycles.exr
DR_EXR=$OUT_DIR/drift.exr
DR_JSON=$OUT_DIR/drift.json

echo "== drift vs Cycles: ${WIDTH}x${HEIGHT}, spp=$SPP, depth=$DEPTH, threads=$THREADS, repeats=$REPEATS"
echo "   drift --max-depth $DEPTH; Cycles max_bounces $((DEPTH + CYCLES_BOUNCES_OFFSET)), cornell_cycles.py args: ${CYCLES_ARGS}"
echo "   host: $(nproc) cpus, load $(cut -d' ' -f1-3 /proc/loadavg), $("$BLENDER" --version 2>/dev/null | head -n1)"

best_cy="" best_cy_sync="" best_dr="" dr_rays="" dr_spp="" cy_mean=""
for rep in $(seq 1 "$REPEATS"); do
    # --- Cycles ---------------------------------------------------------------------------
    # shellcheck disable=SC2086
    TIMEFORMAT='%R %U %S'
    { time "$BLENDER" -b --factory-startup -noaudio --python "$HERE/cornell_cycles.py" -- \
        --spp "$SPP" --max-depth "$DEPTH" --bounces-offset "$CYCLES_BOUNCES_OFFSET" \
        --threads "$THREADS" --width "$WIDTH" --height "$HEIGHT" --seed "$SEED" \
        --out "$CY_EXR" ${CYCLES_ARGS} >"$OUT_DIR/cycles.log" 2>&1 || {
        echo "run_compare: Cycles render failed, see $OUT_DIR/cycles.log" >&2; tail -n 20 "$OUT_DIR/cycles.log" >&2; exit 1; }
    } 2>"$OUT_DIR/cycles.time"
    line=$(grep '^CYCLES_TIME ' "$OUT_DIR/cycles.log" | tail -n1)
    cy_mean=$(grep '^CYCLES_MEAN ' "$OUT_DIR/cycles.log" | tail -n1 | cut -d' ' -f2-)
    cy_s=$(sed -n 's/.*render_seconds=\([^ ]*\).*/\1/p' <<<"$line")
    cy_sync=$(sed -n 's/.*sync_seconds=\([^ ]*\).*/\1/p' <<<"$line")
    echo "   [$rep] $line"
    grep '^CYCLES_CONFIG ' "$OUT_DIR/cycles.log" | tail -n1 | sed "s/^/   [$rep] /"
    cpu_line=$(grep '^CYCLES_TIME_DETAIL ' "$OUT_DIR/cycles.log" | tail -n1 | sed -n 's/.*\(render_cpu_seconds=[^ ]*\).*/\1/p')
    read -r w u s <"$OUT_DIR/cycles.time"
    echo "   [$rep] cycles process: wall ${w}s cpu $(awk "BEGIN{print $u+$s}")s; path tracing $cpu_line (cpu/wall far below threads = CPU contention)"
    if [ -z "$best_cy" ] || awk "BEGIN{exit !($cy_s < $best_cy)}"; then best_cy=$cy_s best_cy_sync=$cy_sync; fi

    # --- drift ----------------------------------------------------------------------------
    rm -f "$DR_JSON"
    drift_cmd=("$DRIFT_BIN" render --mode reference --spp "$SPP" --max-depth "$DEPTH"
               --threads "$THREADS" --width "$WIDTH" --height "$HEIGHT"
               --out "$DR_EXR" --stats "$DR_JSON")
    [ -n "${DRIFT_SCENE:-}" ] && drift_cmd+=(--scene "$DRIFT_SCENE")
    # shellcheck disable=SC2206
    [ -n "${DRIFT_ARGS:-}" ] && drift_cmd+=(${DRIFT_ARGS})
    if ! { time "${drift_cmd[@]}" >"$OUT_DIR/drift.log" 2>&1; } 2>"$OUT_DIR/drift.time"; then
        echo "run_compare: drift render failed (${drift_cmd[*]}), see $OUT_DIR/drift.log:" >&2
        tail -n 20 "$OUT_DIR/drift.log" >&2
        exit 1
    fi
    read -r w u s <"$OUT_DIR/drift.time"
    echo "   [$rep] drift process: wall ${w}s cpu $(awk "BEGIN{print $u+$s}")s (includes load/accel/write)"
    if [ ! -s "$DR_JSON" ]; then
        echo "run_compare: drift wrote no stats JSON ($DR_JSON)" >&2; exit 1
    fi
    read -r dr_ms dr_spp dr_rays < <(python3 - "$DR_JSON" <<'EOF'
import json, sys
s = json.load(open(sys.argv[1]))
ms = s.get("milliseconds", {})
render = ms.get("render") if isinstance(ms, dict) else None
if render is None:
    sys.exit("drift stats: no milliseconds.render in " + sys.argv[1])
rays = s.get("rays", "nan")
if isinstance(rays, dict):  # drift: {"camera":..,"shadow":..,"bounce":..,"total":..}
    rays = rays.get("total", sum(v for v in rays.values() if isinstance(v, (int, float))))
print(float(render), s.get("spp", "nan"), rays)
EOF
)
    dr_s=$(awk "BEGIN{printf \"%.6f\", $dr_ms/1000.0}")
    echo "   [$rep] DRIFT_TIME render_seconds=$dr_s spp=$dr_spp rays=$dr_rays"
    if [ "$dr_spp" != "$SPP" ]; then
        echo "run_compare: WARNING drift stats report spp=$dr_spp, asked for $SPP" >&2
    fi
    if [ -z "$best_dr" ] || awk "BEGIN{exit !($dr_s < $best_dr)}"; then best_dr=$dr_s; fi
done

px=$((WIDTH * HEIGHT))
echo
echo "== time per sample per pixel (path tracing only; best of $REPEATS)"
awk -v cy="$best_cy" -v cys="$best_cy_sync" -v dr="$best_dr" -v spp="$SPP" -v px="$px" \
    -v rays="$dr_rays" 'BEGIN {
    cyn = cy * 1e9 / (spp * px); drn = dr * 1e9 / (spp * px);
    printf "   cycles : %10.4f s  %10.2f ns/(spp*px)   (scene sync+BVH %.3f s, excluded)\n", cy, cyn, cys;
    printf "   drift  : %10.4f s  %10.2f ns/(spp*px)", dr, drn;
    if (rays == rays + 0 && rays > 0 && dr > 0) printf "   (%.2f Mrays/s, %.1f rays/sample)", rays / dr / 1e6, rays / (spp * px);
    printf "\n   ratio drift/cycles = %.3f  (< 1: drift faster)\n", drn / cyn;
}'

echo
echo "== image agreement"
echo "   CYCLES_MEAN $cy_mean"
python3 "$HERE/exr_mean.py" "$CY_EXR" "$DR_EXR" | sed 's/^/   /' || true
echo "   $DRIFT_BIN diff $CY_EXR $DR_EXR --json"
set +e
"$DRIFT_BIN" diff "$CY_EXR" "$DR_EXR" --json
rc=$?
set -e
echo "   (diff exit status $rc; outputs in $OUT_DIR)"
