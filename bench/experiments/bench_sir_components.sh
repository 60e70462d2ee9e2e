#!/usr/bin/env bash
# SIR's component refinement against the whole trace on issue 17's open glossy room and the
# SIR hall, each pair back to back (docs/benchmarks.md, "SIR: component refinement").
# usage: bench/experiments/bench_sir_components.sh [DRIFT_BINARY] [OUT_DIR]
set -euo pipefail
drift=${1:-build/release/bin/drift}
out=${2:-/tmp/sir_components}
mkdir -p "$out"
run() { # name, args...
    local name=$1
    shift
    "$drift" bench sir "$@" --spp 16 --threads 2 --json >"$out/$name.json"
}
for rep in 1 2; do
    run "open320_whole_$rep" scenes/open-glossy/open_glossy.json --sizes 320x240
    run "open320_components_$rep" scenes/open-glossy/open_glossy.json --sizes 320x240 --components
done
run open640_whole scenes/open-glossy/open_glossy.json --sizes 640x480
run open640_components scenes/open-glossy/open_glossy.json --sizes 640x480 --components
hall=(scenes/sir-hall/sir_hall.json --views scenes/sir-hall/sir_views_few.json --sizes 400x300)
run hall_whole "${hall[@]}"
run hall_components "${hall[@]}" --components
python3 "$(dirname "$0")/sir_summary.py" "$out"
