#!/usr/bin/env bash
# Each fast technique of the hybrid frame against a path-traced reference on a GGX scene
# (issue 41; docs/lab/2026-12-07-issue-41-s2.md). One effect varied at a time from the
# hybrid frame's defaults; prints "effect technique FLIP frame-ms" rows.
#   scripts/ggx_techniques.sh DRIFT SCENE REF.exr WIDTH HEIGHT [OUTDIR]
# Make the reference with: drift render SCENE --width W --height H --spp 1024 --out REF.exr
set -euo pipefail
drift=$1 scene=$2 ref=$3 w=$4 h=$5
out=${6:-$(mktemp -d)}
mkdir -p "$out"
run() { # effect technique extra...
    local effect=$1 tech=$2
    shift 2
    local img="$out/${effect}_${tech}.exr"
    nice "$drift" render "$scene" --mode hybrid --width "$w" --height "$h" --threads 2 --quiet \
        "--$effect" "$tech" "$@" --out "$img" --stats "$out/${effect}_${tech}.json" >/dev/null
    local flip ms
    flip=$("$drift" diff "$ref" "$img" | awk '$1 == "flip" { print $2 }')
    ms=$(python3 -c 'import json, sys; print("%.0f" % json.load(open(sys.argv[1]))["milliseconds"]["frame"])' \
        "$out/${effect}_${tech}.json" 2>/dev/null || echo "?")
    printf '%-12s %-8s FLIP %.4f  frame %s ms\n' "$effect" "$tech" "$flip" "$ms"
}
for t in sharp envmap isg aaf micro; do run reflections "$t"; done
for t in ism micro aaf; do run indirect "$t"; done
for t in hard isg aaf; do run shadows "$t"; done
