#!/usr/bin/env bash
# glTF COLOR_0 against Blender: tests/data/vertex_colors/painted.glb, an ico sphere whose
# vertex colours feed its base colour in Blender, exported with COLOR_0, rendered by drift and
# by Cycles 3.4 through Blender's glTF importer (cycles_128x72.exr, 1024 spp, cached by
# make_reference.sh there; no Blender at test time). drift at 128 spp must be within ꟻLIP 0.03
# in the path tracer and 0.15 in the default hybrid frame; the same file without COLOR_0 (the
# sphere white, as drift drew it before) must not be (ꟻLIP > 0.15 in the path tracer).
# $1 is the drift binary.
# ctest-labels: quality
set -u
drift="$1"
here="$(dirname "$0")"
src="$(cd "$here/../.." && pwd)"
source "$here/common.sh"
data="$src/tests/data/vertex_colors"

flip_of() { # scene [render options] -> prints ꟻLIP against Cycles
    local scene="$1"
    shift
    expect 0 "$drift" render "$scene" --width 128 --height 72 --threads 2 --checkpoint 0 \
        --quiet --out "$tmp/r.exr" "$@"
    expect 0 "$drift" diff "$data/cycles_128x72.exr" "$tmp/r.exr" --json
    python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["flip"])' "$tmp/out"
}

# The .glb without COLOR_0 (the JSON chunk rewritten, padded to 4 bytes).
python3 - "$data/painted.glb" "$tmp/plain.glb" <<'PY' || fail "cannot write the variant"
import json, struct, sys
data = open(sys.argv[1], "rb").read()
n = struct.unpack("<I", data[12:16])[0]
g = json.loads(data[20:20 + n])
for mesh in g["meshes"]:
    for p in mesh["primitives"]:
        p["attributes"].pop("COLOR_0", None)
text = json.dumps(g).encode()
text += b" " * (-len(text) % 4)
body = struct.pack("<I", len(text)) + b"JSON" + text + data[20 + n:]
open(sys.argv[2], "wb").write(b"glTF" + struct.pack("<II", 2, 12 + len(body)) + body)
PY
pt=$(flip_of "$data/painted.glb" --spp 128)
hybrid=$(flip_of "$data/painted.glb" --mode hybrid)
plain=$(flip_of "$tmp/plain.glb" --spp 128)
echo "cli.vertex_colors: FLIP path tracer $pt (<= 0.03), hybrid $hybrid (<= 0.15); without COLOR_0 $plain (> 0.15)"
python3 -c 'import sys; p, h, w = map(float, sys.argv[1:]); sys.exit(0 if p <= 0.03 and h <= 0.15 and w > 0.15 else 1)' \
    "$pt" "$hybrid" "$plain" || fail "COLOR_0 does not multiply the base colour as Blender's importer does"

[ "$failures" -eq 0 ] && echo "cli.vertex_colors: ok"
exit $((failures > 0))
