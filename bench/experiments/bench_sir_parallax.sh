#!/usr/bin/env bash
# SIR with the raster's environment map looked up plainly and box-projected (parallax-
# corrected), component refinement on, each pair back to back, on issue 17's open glossy room
# and the SIR hall (docs/benchmarks.md, "SIR: parallax-corrected environment map").
# usage: bench/experiments/bench_sir_parallax.sh [DRIFT_BINARY] [OUT_DIR] [REPEATS]
set -euo pipefail
drift=${1:-build/release/bin/drift}
out=${2:-/tmp/sir_parallax}
repeats=${3:-2}
mkdir -p "$out"
run() { # name, args...
    local name=$1
    shift
    "$drift" bench sir "$@" --spp 16 --threads 2 --components --json >"$out/$name.json"
}
for rep in $(seq "$repeats"); do
    run "open320_none_$rep" scenes/open-glossy/open_glossy.json --sizes 320x240 --envmap-parallax none
    run "open320_box_$rep" scenes/open-glossy/open_glossy.json --sizes 320x240 --envmap-parallax box
done
hall=(scenes/sir-hall/sir_hall.json --views scenes/sir-hall/sir_views_few.json --sizes 400x300)
run hall_none "${hall[@]}" --envmap-parallax none
run hall_box "${hall[@]}" --envmap-parallax box
python3 "$(dirname "$0")/sir_summary.py" "$out"
