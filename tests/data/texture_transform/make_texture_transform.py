#!/usr/bin/env python3
# Writes tt.gltf and tex.png here: a quad facing the camera whose emissive texture (a 4 x 4
# image of coloured quadrants, one texel yellow) goes through KHR_texture_transform (offset
# (0.2, 0.1), rotation 0.5 rad, scale (1.5, 1)) with a nearest, repeating sampler. Emission
# only (black base): the image is the texture as each renderer maps it.
# tests/cli/test_texture_transform.sh compares drift with Cycles' render of it
# (make_reference.sh: Blender's glTF importer turns the transform into a Mapping node).
import base64
import json
import os
import struct
import zlib

here = os.path.dirname(os.path.abspath(__file__))


def png(w, h, px):
    rows = b"".join(b"\0" + bytes(px[y * w * 3:(y + 1) * w * 3]) for y in range(h))

    def chunk(tag, data):
        return (struct.pack(">I", len(data)) + tag + data +
                struct.pack(">I", zlib.crc32(tag + data) & 0xFFFFFFFF))
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0)) +
            chunk(b"IDAT", zlib.compress(rows)) + chunk(b"IEND", b""))


quadrants = {(0, 0): (255, 0, 0), (1, 0): (0, 255, 0), (0, 1): (0, 0, 255), (1, 1): (255, 255, 255)}
px = []
for y in range(4):
    for x in range(4):
        px += list((255, 255, 0) if (x, y) == (0, 0) else quadrants[(x // 2, y // 2)])
with open(os.path.join(here, "tex.png"), "wb") as f:
    f.write(png(4, 4, px))

pos = [-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0]
uv = [0, 1, 1, 1, 1, 0, 0, 0]
buf = (struct.pack("<12f", *pos) + struct.pack("<12f", *([0, 0, 1] * 4)) +
       struct.pack("<8f", *uv) + struct.pack("<6H", 0, 1, 2, 0, 2, 3))
views = [(0, 48), (48, 48), (96, 32), (128, 12)]
gltf = {
    "asset": {"version": "2.0"},
    "extensionsUsed": ["KHR_texture_transform"],
    "scene": 0, "scenes": [{"nodes": [0, 1]}],
    "nodes": [{"mesh": 0}, {"camera": 0, "translation": [0, 0, 3]}],
    "cameras": [{"type": "perspective",
                 "perspective": {"yfov": 0.8, "aspectRatio": 1.0, "znear": 0.1}}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2},
                                "indices": 3, "material": 0}]}],
    "materials": [{"name": "transformed", "emissiveFactor": [1, 1, 1],
                   "pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1],
                                            "metallicFactor": 0, "roughnessFactor": 1},
                   "emissiveTexture": {"index": 0, "extensions": {"KHR_texture_transform": {
                       "offset": [0.2, 0.1], "rotation": 0.5, "scale": [1.5, 1.0]}}}}],
    "samplers": [{"magFilter": 9728, "minFilter": 9728, "wrapS": 10497, "wrapT": 10497}],
    "textures": [{"source": 0, "sampler": 0}],
    "images": [{"uri": "tex.png"}],
    "buffers": [{"byteLength": len(buf),
                 "uri": "data:application/octet-stream;base64," + base64.b64encode(buf).decode()}],
    "bufferViews": [{"buffer": 0, "byteOffset": o, "byteLength": n} for o, n in views],
    "accessors": [
        {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
         "min": [-1, -1, 0], "max": [1, 1, 0]},
        {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3"},
        {"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC2"},
        {"bufferView": 3, "componentType": 5123, "count": 6, "type": "SCALAR"}],
}
with open(os.path.join(here, "tt.gltf"), "w") as f:
    json.dump(gltf, f, indent=1)
