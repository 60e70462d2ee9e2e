#!/usr/bin/env bash
# drift render's glTF options (issue 42): --camera NAME picks a glTF file's camera by name or
# index (the same image both ways, another than the first camera's), an unknown name is an
# error that lists the file's cameras, a JSON scene is told where its camera is chosen; and
# --aov-normal Normal writes the normals as Blender's compositor names them (Normal.X/Y/Z)
# where the default is N.X/N.Y/N.Z.
# $1 is the drift binary.
set -u
drift="$1"
here="$(dirname "$0")"
src="$(cd "$here/../.." && pwd)"
source "$here/common.sh"

# issue 22's Blender scene with a second camera, "Side", on a node of its own.
python3 - "$src/tests/data/gltf/blender_scene.gltf" "$tmp/two.gltf" <<'PY' || fail "cannot write the glTF"
import json, sys
j = json.load(open(sys.argv[1]))
j["cameras"].append({"name": "Side", "type": "perspective",
                     "perspective": {"aspectRatio": 1.0, "yfov": 0.8, "znear": 0.1}})
j["nodes"].append({"name": "SideNode", "camera": len(j["cameras"]) - 1, "translation": [6, 2, 6],
                   "rotation": [-0.0828, 0.3799, 0.0341, 0.9206]})
j["scenes"][0]["nodes"].append(len(j["nodes"]) - 1)
json.dump(j, open(sys.argv[2], "w"))
PY

render() { # name args...
    local name="$1"
    shift
    expect 0 "$drift" render "$tmp/two.gltf" --spp 2 --width 24 --height 16 --threads 2 \
        --checkpoint 0 --quiet --out "$tmp/$name.exr" "$@"
}
render first
render side --camera Side
render side1 --camera 1
cmp -s "$tmp/side.exr" "$tmp/side1.exr" || fail "--camera Side and --camera 1 differ"
cmp -s "$tmp/first.exr" "$tmp/side.exr" && fail "--camera Side renders the first camera's view"
render camera --camera Camera
cmp -s "$tmp/first.exr" "$tmp/camera.exr" || fail "--camera Camera is not the default (first) camera"

expect 1 "$drift" render "$tmp/two.gltf" --camera Top --spp 1 --width 8 --height 8 --quiet \
    --checkpoint 0 --out "$tmp/top.exr"
grep -q "no camera named or numbered 'Top'" "$tmp/err" || fail "unknown camera: $(cat "$tmp/err")"
grep -q "0 'Camera', 1 'Side'" "$tmp/err" || fail "the error does not list the cameras: $(cat "$tmp/err")"
[ -e "$tmp/top.exr" ] && fail "an unknown camera still wrote an image"
printf '{"version": 1, "meshes": [{"path": "two.gltf"}]}' >"$tmp/scene.json"
expect 1 "$drift" render "$tmp/scene.json" --camera Side --spp 1 --width 8 --height 8 --quiet \
    --checkpoint 0 --out "$tmp/json.exr"
grep -q "mesh entry's \"camera\"" "$tmp/err" || fail "JSON scene + --camera: $(cat "$tmp/err")"

# The normals' channel names in the EXR header.
channels() {
    python3 - "$1" <<'PY'
import sys
data = open(sys.argv[1], "rb").read(65536)
at = data.index(b"channels\0chlist\0") + len(b"channels\0chlist\0") + 4
names = []
while data[at] != 0:
    end = data.index(b"\0", at)
    names.append(data[at:end].decode())
    at = end + 1 + 16
print(" ".join(names))
PY
}
render aov --aov
render aov_blender --aov --aov-normal Normal
channels "$tmp/aov.exr" >"$tmp/names_n"
channels "$tmp/aov_blender.exr" >"$tmp/names_blender"
grep -qw "N.X" "$tmp/names_n" || fail "default normals not N.X: $(cat "$tmp/names_n")"
for c in Normal.X Normal.Y Normal.Z; do
    grep -qw "$c" "$tmp/names_blender" || fail "--aov-normal Normal: no $c in $(cat "$tmp/names_blender")"
done
grep -qw "N.X" "$tmp/names_blender" && fail "--aov-normal Normal still writes N.X"
expect 2 "$drift" render "$tmp/two.gltf" --aov --aov-normal normals --quiet --out "$tmp/bad.exr"

[ "$failures" -eq 0 ] && echo "cli.gltf_options: ok"
exit $((failures > 0))
