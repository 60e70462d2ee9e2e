#!/usr/bin/env bash
# Regenerates src/scene/ggx_tables.inc (the GGX albedo tables of docs/materials.md) from the
# integrals in src/scene/microfacet.c (and the multiple-scattering lobe's scale fitted to
# them). About a minute on one core.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
cc -O2 -std=c11 -D_POSIX_C_SOURCE=200809L -I"$root/include" -I"$root/src" \
  "$root/scripts/gen_ggx_tables.c" "$root/src/scene/microfacet.c" -lm -o "$tmp/gen"
"$tmp/gen" > "$tmp/ggx_tables.inc"
mv "$tmp/ggx_tables.inc" "$root/src/scene/ggx_tables.inc"
echo "wrote src/scene/ggx_tables.inc"
