#!/usr/bin/env bash
# Spot checks of the equal-time frontier (docs/frontier.md): a few chosen rows of one scene at
# one size, each timed RUNS times (the median frame ms; hybrid rows over --frames 4, whose
# steady-state frame is reported) and scored against a reference the caller made once, e.g.
#   drift render SCENE --mode reference --width 400 --height 400 --spp 512 --max-depth 8 --out ref.exr
# Every row is one line: a label, then drift render's options (the scene, size, threads,
# depth and output are added here). A pt row is --mode reference; a hybrid row --mode hybrid.
#   BIN=build/release/bin/drift bash bench/experiments/frontier-spot.sh SCENE REF.exr SIZE ROWS.txt
# prints | row | ms | FLIP | RMSE | in Markdown. The full sweep is `drift bench frontier`; this
# is for re-measuring a handful of budget edges on a quiet machine.
set -eu
bin=${BIN:-drift}
runs=${RUNS:-3}
threads=${THREADS:-2}
scene=$1 ref=$2 size=$3 rows=$4
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
echo "| row | ms | FLIP | RMSE |"
echo "|---|---|---|---|"
while IFS='|' read -r label args; do
    [ -z "$label" ] || [ "${label#\#}" != "$label" ] && continue
    ms=()
    for ((k = 0; k < runs; ++k)); do
        extra=()
        case " $args " in *" --mode hybrid "*) extra=(--frames 4) ;; esac
        # shellcheck disable=SC2086 # the row's options are words
        "$bin" render "$scene" $args "${extra[@]}" --width "$size" --height "$size" \
            --threads "$threads" --max-depth 8 --quiet --out "$work/out.exr" \
            --stats "$work/stats.json" >/dev/null
        # A pt row's ms: the render plus --denoise's filter (which runs as the image is written).
        ms+=("$(python3 -c 'import json,sys; m=json.load(open(sys.argv[1]))["milliseconds"]; print(m["frame"] if "frame" in m else m["render"] + m.get("denoise", 0))' "$work/stats.json")")
    done
    median=$(printf '%s\n' "${ms[@]}" | sort -g | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}')
    scores=$("$bin" diff "$ref" "$work/out.exr")
    flip=$(awk '$1 == "flip" {print $2}' <<<"$scores")
    rmse=$(awk '$1 == "rmse" {print $2}' <<<"$scores")
    printf '| %s | %.1f | %.4f | %.4f |\n' "$label" "$median" "$flip" "$rmse"
done <"$rows"
