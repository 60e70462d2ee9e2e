#!/usr/bin/env bash
# Files a user already has (issue 42): scenes Blender 3.4 wrote with its own exporters render
# in drift as Cycles renders them in Blender. The files and the Cycles references are in
# tests/data/interchange (made by make_interchange.py there: Blender runs only to regenerate
# them, so this test needs no Blender):
#   textured.glb   an image texture embedded in the .glb (a bufferView), one point light
#   lights.glb     a point and a spot light (the spot's cone as Cycles draws it)
#   emissive.glb   an emissive quad as the only light (KHR_materials_emissive_strength)
#   emissive.obj   the same scene through Blender's OBJ exporter (map_Kd without Kd, s 1
#                  without normals), framed by emissive_obj.json (OBJ has no camera)
# and textured.glb rewritten as a .gltf with data: URIs renders as the .glb.
# Each: drift at 256 spp, 40×30, within ꟻLIP 0.05 of Cycles (2048 spp) and 3% in mean
# luminance. Then the OBJ/MTL details Blender's files need: trailing whitespace after map_Kd,
# a missing .mtl or texture named with its file and line.
# $1 is the drift binary.
set -u
drift="$1"
here="$(dirname "$0")"
src="$(cd "$here/../.." && pwd)"
data="$src/tests/data/interchange"
source "$here/common.sh"

compare() { # name scene reference
    local name="$1" scene="$2" reference="$3"
    expect 0 "$drift" render "$scene" --spp 256 --width 40 --height 30 --threads 2 --seed 1 \
        --checkpoint 0 --quiet --out "$tmp/$name.exr"
    grep -qi "warn" "$tmp/err" && fail "$name: warnings: $(cat "$tmp/err")"
    expect 0 "$drift" diff "$reference" "$tmp/$name.exr" --json
    cp "$tmp/out" "$tmp/$name.json"
    python3 - "$name" "$tmp/$name.json" "$src/bench/cycles/exr_mean.py" "$reference" \
        "$tmp/$name.exr" <<'PY' || fail "$name: drift and Cycles disagree"
import json, subprocess, sys
name, diff, mean_py = sys.argv[1:4]
flip = json.load(open(diff))["flip"]
lum = []
for f in sys.argv[4:]:
    out = subprocess.run([sys.executable, mean_py, f], capture_output=True, text=True,
                         check=True).stdout.split()
    r, g, b = (float(x) for x in out[1:4])
    lum.append(0.2126 * r + 0.7152 * g + 0.0722 * b)
ratio = lum[1] / lum[0]
print("cli.interchange: %-9s FLIP %.4f (<= 0.05), mean luminance drift/Cycles %.4f (within 3%%)"
      % (name, flip, ratio))
sys.exit(0 if flip <= 0.05 and abs(ratio - 1.0) <= 0.03 else 1)
PY
}

compare textured "$data/textured.glb" "$data/cycles_textured.exr"
compare lights "$data/lights.glb" "$data/cycles_lights.exr"
compare emissive "$data/emissive.glb" "$data/cycles_emissive.exr"
compare obj "$data/emissive_obj.json" "$data/cycles_emissive.exr"

# The .glb's texture is read from inside it.
expect 0 "$drift" info "$data/textured.glb"
grep -q "^textures *1$" "$tmp/out" || fail "textured.glb: its embedded texture was not loaded"

# The same file as a .gltf with data: URIs (buffer and image) renders as the .glb.
python3 - "$data/textured.glb" "$tmp/datauri.gltf" <<'PY' || fail "cannot write the data-URI glTF"
import base64, json, struct, sys
d = open(sys.argv[1], "rb").read()
n = struct.unpack("<I", d[12:16])[0]
j = json.loads(d[20:20 + n])
b = d[28 + n:28 + n + struct.unpack("<I", d[20 + n:24 + n])[0]]
image = j["images"][0]
view = j["bufferViews"][image.pop("bufferView")]
start = view.get("byteOffset", 0)
image["uri"] = "data:image/png;base64," + base64.b64encode(b[start:start + view["byteLength"]]).decode()
j["buffers"][0]["uri"] = "data:application/octet-stream;base64," + base64.b64encode(b).decode()
json.dump(j, open(sys.argv[2], "w"))
PY
tiny=(--spp 2 --width 16 --height 12 --threads 2 --checkpoint 0 --quiet --seed 4)
expect 0 "$drift" render "$tmp/datauri.gltf" "${tiny[@]}" --out "$tmp/datauri.exr"
grep -qi "warn" "$tmp/err" && fail "data-URI glTF: warnings: $(cat "$tmp/err")"
expect 0 "$drift" render "$data/textured.glb" "${tiny[@]}" --out "$tmp/glb.exr"
expect 0 "$drift" diff "$tmp/glb.exr" "$tmp/datauri.exr" --json
grep -q '"rmse": 0[,}]' "$tmp/out" || fail "the data-URI .gltf and the .glb differ: $(cat "$tmp/out")"

# Smoothing groups: the OBJ's sphere (s 1, no normals) shades as the .glb's (with normals);
# with its s 1 turned off it is faceted and further from it.
mkdir -p "$tmp/flat"
cp "$data/emissive.mtl" "$data/checker.png" "$data/emissive_obj.json" "$tmp/flat/"
sed 's/^s 1$/s 0/' "$data/emissive.obj" >"$tmp/flat/emissive.obj"
mid=(--spp 16 --width 40 --height 30 --threads 2 --checkpoint 0 --quiet --seed 4)
expect 0 "$drift" render "$data/emissive.glb" "${mid[@]}" --out "$tmp/s_glb.exr"
expect 0 "$drift" render "$data/emissive_obj.json" "${mid[@]}" --out "$tmp/s_smooth.exr"
expect 0 "$drift" render "$tmp/flat/emissive_obj.json" "${mid[@]}" --out "$tmp/s_flat.exr"
expect 0 "$drift" diff "$tmp/s_glb.exr" "$tmp/s_smooth.exr" --json
cp "$tmp/out" "$tmp/s_smooth.json"
expect 0 "$drift" diff "$tmp/s_glb.exr" "$tmp/s_flat.exr" --json
cp "$tmp/out" "$tmp/s_flat.json"
expect 0 "$drift" diff "$tmp/s_smooth.exr" "$tmp/s_flat.exr" --json
# The .glb's materials are GGX (glTF metallic-roughness) and the OBJ's the MTL's mapping, so
# both OBJ renders keep a material difference from the .glb: s 1 must change the image
# (interpolated normals) and bring it closer to the .glb's, which has the normals.
python3 - "$tmp/s_smooth.json" "$tmp/s_flat.json" "$tmp/out" <<'PY' || fail "s 1 without normals is not shaded smooth"
import json, sys
smooth, flat, between = (json.load(open(p))["rmse"] for p in sys.argv[1:4])
print("cli.interchange: OBJ against .glb: rmse %.5f with s 1, %.5f faceted; %.5f between them"
      % (smooth, flat, between))
sys.exit(0 if smooth < flat and between > 0.25 * flat else 1)
PY

# OBJ/MTL: a map_Kd with trailing tabs and spaces loads its texture; a missing texture and a
# missing .mtl are warnings naming the file and line that named them.
mkdir -p "$tmp/obj"
cp "$data/checker.png" "$tmp/obj/"
cat >"$tmp/obj/quad.obj" <<'EOF'
mtllib quad.mtl
o Quad
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
vt 0 0
vt 1 0
vt 1 1
vt 0 1
usemtl Tex
f 1/1 2/2 3/3 4/4
EOF
printf 'newmtl Tex\nKd 1 1 1\nmap_Kd checker.png \t \n' >"$tmp/obj/quad.mtl"
expect 0 "$drift" info "$tmp/obj/quad.obj"
grep -q "^textures *1$" "$tmp/out" || fail "map_Kd with trailing whitespace: no texture"
grep -qi "warn" "$tmp/err" && fail "map_Kd with trailing whitespace: $(cat "$tmp/err")"
printf 'newmtl Tex\nKd 1 1 1\n\nmap_Kd nothere.png\n' >"$tmp/obj/quad.mtl"
expect 0 "$drift" info "$tmp/obj/quad.obj"
grep -q "quad.mtl:4.*nothere.png" "$tmp/err" ||
    fail "a missing texture is not named with its MTL file and line: $(cat "$tmp/err")"
rm "$tmp/obj/quad.mtl"
expect 0 "$drift" info "$tmp/obj/quad.obj"
grep -q "quad.obj:1.*quad.mtl" "$tmp/err" ||
    fail "a missing .mtl is not named with the OBJ's file and line: $(cat "$tmp/err")"

if [ "$failures" -ne 0 ]; then
    echo "$failures failure(s)" >&2
    exit 1
fi
echo "cli.interchange: ok"
