#!/usr/bin/env bash
# KHR_texture_transform against Blender (issue 41): tests/data/texture_transform/tt.gltf, an
# emissive quad whose 4x4 texture is offset, rotated by 0.5 rad and scaled, rendered by drift
# and by Cycles 3.4 through Blender's glTF importer (cycles_32x32.exr, cached by
# make_reference.sh there; no Blender at test time). drift at 64 spp must be within ꟻLIP 0.06
# (the rest is the quad's and the texels' anti-aliased edges); the same file with the rotation
# reversed, or without the transform, must not be (ꟻLIP > 0.15): the test sees the rotation's
# sense, the offset and the scale.
# $1 is the drift binary.
set -u
drift="$1"
here="$(dirname "$0")"
src="$(cd "$here/../.." && pwd)"
source "$here/common.sh"
data="$src/tests/data/texture_transform"

flip_of() { # scene -> prints ꟻLIP against Cycles
    expect 0 "$drift" render "$1" --spp 64 --width 32 --height 32 --threads 2 --max-depth 1 \
        --checkpoint 0 --quiet --out "$tmp/r.exr"
    expect 0 "$drift" diff "$data/cycles_32x32.exr" "$tmp/r.exr" --json
    python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["flip"])' "$tmp/out"
}

cp "$data/tex.png" "$tmp/"
python3 - "$data/tt.gltf" "$tmp" <<'PY' || fail "cannot write the variants"
import json, sys
g = json.load(open(sys.argv[1]))
t = g["materials"][0]["emissiveTexture"]["extensions"]["KHR_texture_transform"]
t["rotation"] = -t["rotation"]
json.dump(g, open(sys.argv[2] + "/reversed.gltf", "w"))
del g["materials"][0]["emissiveTexture"]["extensions"]
json.dump(g, open(sys.argv[2] + "/plain.gltf", "w"))
PY
good=$(flip_of "$data/tt.gltf")
reversed=$(flip_of "$tmp/reversed.gltf")
plain=$(flip_of "$tmp/plain.gltf")
echo "cli.texture_transform: FLIP $good (<= 0.06); rotation reversed $reversed, no transform $plain (> 0.15)"
python3 -c 'import sys; g, r, p = map(float, sys.argv[1:]); sys.exit(0 if g <= 0.06 and r > 0.15 and p > 0.15 else 1)' \
    "$good" "$reversed" "$plain" || fail "KHR_texture_transform does not map as Blender's importer does"

[ "$failures" -eq 0 ] && echo "cli.texture_transform: ok"
exit $((failures > 0))
