#!/usr/bin/env bash
# drift info on bad scene files: each must exit non-zero (1 = could not load, 2 = usage),
# name the file in its message, and not crash (exit status < 128, no sanitizer report).
# Usage: test_bad_input.sh path/to/drift
set -u
drift=${1:?usage: test_bad_input.sh path/to/drift}
source "$(dirname "$0")/common.sh"
dir="$tmp"

# expect_failure NAME: runs drift info on $dir/NAME and checks status and message.
expect_failure() {
    local name=$1 file="$dir/$1" status
    "$drift" info "$file" >"$dir/out" 2>"$dir/err"
    status=$?
    if [ "$status" -eq 0 ]; then
        fail "$name: exit status 0"
    elif [ "$status" -ge 128 ]; then
        fail "$name: crashed (exit status $status)"
    fi
    if ! grep -qF "$name" "$dir/err"; then
        fail "$name: the message does not name the file:"
        sed 's/^/    /' "$dir/err" >&2
    fi
    if grep -qE "AddressSanitizer|LeakSanitizer|runtime error" "$dir/err"; then
        fail "$name: sanitizer report:"
        sed 's/^/    /' "$dir/err" >&2
    fi
}

# expect_line NAME LINE: the message points at line LINE of the file.
expect_line() {
    if ! grep -qF "$1:$2" "$dir/err"; then
        fail "$1: no message at line $2:"
        sed 's/^/    /' "$dir/err" >&2
    fi
}

printf '{\n  "camera": {\n    "position": [1, 2,\n  }\n}\n' >"$dir/malformed.json"
expect_failure malformed.json
expect_line malformed.json 4

printf '' >"$dir/empty.json"
expect_failure empty.json

printf '{\n "camera": { "position": [0,0,1], "target": [0,0,0],\n   "fov_y": "wide" }\n}\n' \
    >"$dir/wrong_type.json"
expect_failure wrong_type.json
expect_line wrong_type.json 3

printf '{\n "camera": { "position": [0,0,1], "target": [0,0,0],\n   "width": 1000000000 }\n}\n' \
    >"$dir/absurd_width.json"
expect_failure absurd_width.json
expect_line absurd_width.json 3

printf '{\n "lights": [\n  { "type": "point", "position": [0, 1e999, 0], "intensity": 1 }\n ]\n}\n' \
    >"$dir/infinite.json"
expect_failure infinite.json
expect_line infinite.json 3

printf '{\n "lights": [\n  { "type": "quad", "corner": [0,0,0], "edge_u": [1,0,0],\n    "edge_v": [0,0,0], "radiance": 1 }\n ]\n}\n' \
    >"$dir/zero_area.json"
expect_failure zero_area.json
expect_line zero_area.json 3

printf '{\n "lights": [ { "type": "sphere", "center": [0,0,0],\n   "radius": -2, "radiance": 1 } ]\n}\n' \
    >"$dir/negative_radius.json"
expect_failure negative_radius.json

printf '{\n "meshes": [\n  { "path": "missing_mesh.obj" }\n ]\n}\n' >"$dir/missing_mesh.json"
expect_failure missing_mesh.json
expect_line missing_mesh.json 3

printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99\n' >"$dir/bad_index.obj"
expect_failure bad_index.obj

printf 'ply\nformat ascii 1.0\nelement vertex 1000000000\nproperty float x\nproperty float y\nproperty float z\nend_header\n0 0 0\n' \
    >"$dir/huge.ply"
expect_failure huge.ply

printf 'not gzip at all' >"$dir/fake.obj.gz"
expect_failure fake.obj.gz

printf 'solid x\nendsolid x\n' >"$dir/model.stl"
expect_failure model.stl

expect_failure does_not_exist.json

mkdir "$dir/folder.obj"
expect_failure folder.obj

# Usage errors exit 2; --help exits 0.
"$drift" info --no-such-flag >/dev/null 2>&1
[ $? -eq 2 ] || fail "unknown option: expected exit status 2"
"$drift" info --help >/dev/null 2>&1 || fail "--help: expected exit status 0"

# The default scene loads; --json is valid JSON with the expected counts.
if ! "$drift" info --json >"$dir/info.json" 2>"$dir/err"; then
    fail "default scene: drift info failed"
    sed 's/^/    /' "$dir/err" >&2
elif command -v python3 >/dev/null; then
    python3 - "$dir/info.json" <<'EOF' || fail "default scene: unexpected --json output"
import json, sys
info = json.load(open(sys.argv[1]))
assert info["triangles"] == 32, info
assert info["lights"]["triangle"] == 2, info
EOF
fi

# An OBJ cut mid-line (issue 18) is an error naming the file and the line, not a quiet
# load of the triangles before the cut; a file that ends without a newline after a comment
# still loads.
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4 3\nf 1 2 3' >"$dir/cut_face.obj"
expect_failure cut_face.obj
expect_line cut_face.obj 7
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nv 1 1' >"$dir/cut_vertex.obj"
expect_failure cut_vertex.obj
expect_line cut_vertex.obj 5
gzip -c "$dir/cut_face.obj" >"$dir/cut_gz.obj.gz"
expect_failure cut_gz.obj.gz
expect_line cut_gz.obj.gz 7
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n# no newline' >"$dir/no_newline.obj"
"$drift" info "$dir/no_newline.obj" >/dev/null 2>&1 || fail "an OBJ ending in a comment loads"

# PLY errors name the line (ASCII) or the byte and element (binary); assimp names neither
# and loads a file cut short without a word.
ply_head='ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n'
printf "${ply_head}0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n" >"$dir/good.ply"
"$drift" info "$dir/good.ply" >/dev/null 2>"$dir/err" || fail "a small ASCII PLY loads: $(cat "$dir/err")"
printf "${ply_head}0 0 0\n1 0 0\n0 1" >"$dir/cut_mid_line.ply"
expect_failure cut_mid_line.ply
expect_line cut_mid_line.ply 12
printf "${ply_head}0 0 0\n1 0 0\n0 1 0\n" >"$dir/cut_before_face.ply"
expect_failure cut_before_face.ply
expect_line cut_before_face.ply 13
printf "${ply_head}0 0 0\n1 0 0 7\n0 1 0\n3 0 1 2\n" >"$dir/extra_value.ply"
expect_failure extra_value.ply
expect_line extra_value.ply 11
printf "${ply_head}0 0 0\n1 0 0\n0 1 0\n3 0 1\n" >"$dir/short_face.ply"
expect_failure short_face.ply
expect_line short_face.ply 13
printf "${ply_head}0 0 0\n1 x 0\n0 1 0\n3 0 1 2\n" >"$dir/not_number.ply"
expect_failure not_number.ply
expect_line not_number.ply 11
printf 'ply\nformat ascii 1.0\nelement vertex 3\nproperty floot x\nend_header\n0\n0\n0\n' >"$dir/bad_type.ply"
expect_failure bad_type.ply
expect_line bad_type.ply 4
python3 - "$dir/cut_binary.ply" <<'PY'
import struct, sys
head = (b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
        b"property float y\nproperty float z\nelement face 1\n"
        b"property list uchar int vertex_indices\nend_header\n")
body = struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0) + struct.pack("<B3i", 3, 0, 1, 2)
open(sys.argv[1], "wb").write(head + body[:-6])
PY
expect_failure cut_binary.ply
grep -q "byte .*'face' element 1 of 1" "$dir/err" || fail "cut_binary.ply: no byte and element: $(cat "$dir/err")"

# Malformed glTF JSON names its line (cJSON's error position).
printf '{\n  "asset": { "version": "2.0" },\n  "scenes": [ { "nodes": [0] } \n  "nodes": []\n}\n' \
    >"$dir/syntax.gltf"
expect_failure syntax.gltf
expect_line syntax.gltf 4

# A FIFO named as a scene is refused at once, not read forever.
mkfifo "$dir/fifo.json"
timeout 10 "$drift" info "$dir/fifo.json" >"$dir/out" 2>"$dir/err"
[ $? -eq 1 ] && grep -q "fifo.json" "$dir/err" || fail "a FIFO scene is refused at once by name"

# Bad glTF: wrong types, a missing buffer, out-of-range accessors and indices, a light without
# its spot, a .glb cut short, malformed JSON: each an error naming the file.
python3 - "$DRIFT_SOURCE_DIR/tests/data/gltf/blender_scene.gltf" "$dir" <<'PY'
import copy, json, sys
base, out = json.load(open(sys.argv[1])), sys.argv[2]
def write(name, change):
    d = copy.deepcopy(base)
    change(d)
    open(out + "/" + name, "w").write(json.dumps(d))
write("missing_buffer.gltf", lambda d: d["buffers"][0].update(uri="nothere.bin"))
write("long_accessor.gltf", lambda d: d["accessors"][0].update(count=100000))
write("meshes_number.gltf", lambda d: d.update(meshes=5))
write("bad_indices.gltf", lambda d: d["meshes"][0]["primitives"][0].update(indices=999))
write("spot_without_cone.gltf",
      lambda d: d["extensions"]["KHR_lights_punctual"]["lights"][1].pop("spot"))
open(out + "/cut.glb", "wb").write(b"glTF\x02\x00\x00\x00\x10\x00\x00\x00JSON")
open(out + "/braces.gltf", "w").write(json.dumps(base)[:-40])
PY
for name in missing_buffer.gltf long_accessor.gltf meshes_number.gltf bad_indices.gltf \
    spot_without_cone.gltf cut.glb braces.gltf; do
    expect_failure "$name"
done

if [ "$failures" -ne 0 ]; then
    echo "$failures failure(s)" >&2
    exit 1
fi
echo "all bad inputs rejected cleanly"
