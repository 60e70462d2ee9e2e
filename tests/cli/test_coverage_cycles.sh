#!/usr/bin/env bash
# Cut-outs and veils against Blender (issue 41, coverage): tests/data/coverage/cards_blender.glb,
# four foliage cards whose leaf texture's alpha Blender clips (glTF alphaMode MASK) and a veil
# of alpha 0.4 (BLEND), rendered by drift and by Cycles 3.4 through Blender's glTF importer
# (cycles_128x72.exr, 1024 spp, cached by make_reference.sh there; no Blender at test time).
# drift at 128 spp must be within ꟻLIP 0.045 (its own noise is most of it); the same file with
# every alphaMode set to OPAQUE — how drift drew it before — must not be (ꟻLIP > 0.2), nor with
# the veil alone opaque (> 0.06): the test sees both modes.
# $1 is the drift binary.
# ctest-labels: quality
set -u
drift="$1"
here="$(dirname "$0")"
src="$(cd "$here/../.." && pwd)"
source "$here/common.sh"
data="$src/tests/data/coverage"

flip_of() { # scene -> prints ꟻLIP against Cycles
    expect 0 "$drift" render "$1" --spp 128 --width 128 --height 72 --threads 2 \
        --checkpoint 0 --quiet --out "$tmp/r.exr"
    expect 0 "$drift" diff "$data/cycles_128x72.exr" "$tmp/r.exr" --json
    python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["flip"])' "$tmp/out"
}

# The .glb with its materials' alphaMode rewritten (the JSON chunk, padded to 4 bytes).
python3 - "$data/cards_blender.glb" "$tmp" <<'PY' || fail "cannot write the variants"
import json, struct, sys
data = open(sys.argv[1], "rb").read()
n = struct.unpack("<I", data[12:16])[0]
rest = data[20 + n:]
def write(name, change):
    g = json.loads(data[20:20 + n])
    for m in g["materials"]:
        change(m)
    text = json.dumps(g).encode()
    text += b" " * (-len(text) % 4)
    body = struct.pack("<I", len(text)) + b"JSON" + text + rest
    open(sys.argv[2] + "/" + name, "wb").write(b"glTF" + struct.pack("<II", 2, 12 + len(body)) + body)
def all_opaque(m):
    m.pop("alphaMode", None)
def veil_opaque(m):
    if m.get("alphaMode") == "BLEND":
        m.pop("alphaMode")
write("opaque.glb", all_opaque)
write("veil_opaque.glb", veil_opaque)
PY
good=$(flip_of "$data/cards_blender.glb")
opaque=$(flip_of "$tmp/opaque.glb")
veil=$(flip_of "$tmp/veil_opaque.glb")
echo "cli.coverage_cycles: FLIP $good (<= 0.045); all opaque $opaque (> 0.2), veil opaque $veil (> 0.06)"
python3 -c 'import sys; g, o, v = map(float, sys.argv[1:]); sys.exit(0 if g <= 0.045 and o > 0.2 and v > 0.06 else 1)' \
    "$good" "$opaque" "$veil" || fail "alpha MASK and BLEND do not render as Cycles renders them"

[ "$failures" -eq 0 ] && echo "cli.coverage_cycles: ok"
exit $((failures > 0))
