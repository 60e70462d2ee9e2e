#!/usr/bin/env bash
# The GGX conductor's cost per path-tracer bounce (a sample, an eval and a pdf) in this tree
# against revision $1 (default: the commit before the multiple-scattering lobe followed the
# specular lobe), compiled into one program (bench/ggx/conductor_bench.c), one thread, runs
# interleaved, CPU time. usage: scripts/bench_ggx_conductor.sh [revision] [bounces] [runs]
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
rev="${1:-85e323c}"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
git -C "$root" show "$rev:src/scene/ggx.c" > "$tmp/old_ggx.c"
flags=(-O2 -std=c11 -D_POSIX_C_SOURCE=200809L -I"$root/include" -I"$root/src" -I"$root/src/scene")
rename=(-Ddrift__ggx_eval=old_ggx_eval -Ddrift__ggx_pdf=old_ggx_pdf
        -Ddrift__ggx_sample=old_ggx_sample -Ddrift__ggx_is_delta=old_ggx_is_delta
        -Ddrift_ggx_named_metal=old_ggx_named_metal
        -Ddrift_bsdf_ggx_reflection_albedo=old_ggx_reflection_albedo
        -Ddrift_ggx_sample_visible_normal=old_ggx_sample_visible_normal)
cc "${flags[@]}" "${rename[@]}" -c "$tmp/old_ggx.c" -o "$tmp/old_ggx.o"
cc "${flags[@]}" "$root/bench/ggx/conductor_bench.c" "$root/src/scene/ggx.c" \
  "$root/src/scene/microfacet.c" "$root/src/scene/ggx_tables.c" "$root/src/math/warp.c" \
  "$tmp/old_ggx.o" -lm -o "$tmp/bench"
"$tmp/bench" "${2:-2000000}" "${3:-5}"
