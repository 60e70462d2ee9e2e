# Writes the coverage test's images (tests/unit/test_coverage.c): alpha.png, a 4 x 1 RGBA
# image whose alpha is 0, 128, 255, 255 (colour 10, 20, 30 everywhere), and opaque.png, a
# 2 x 1 RGB image (no alpha channel). Run from this folder: python3 make_coverage.py
import struct
import zlib


def png(path, width, rows, colour_type):
    def chunk(kind, data):
        return (struct.pack(">I", len(data)) + kind + data +
                struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF))
    raw = b"".join(b"\x00" + bytes(row) for row in rows)
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n")
        f.write(chunk(b"IHDR", struct.pack(">IIBBBBB", width, len(rows), 8, colour_type, 0, 0, 0)))
        f.write(chunk(b"IDAT", zlib.compress(raw)))
        f.write(chunk(b"IEND", b""))


png("alpha.png", 4, [[10, 20, 30, 0, 10, 20, 30, 128, 10, 20, 30, 255, 10, 20, 30, 255]], 6)
png("opaque.png", 2, [[200, 100, 50, 200, 100, 50]], 2)

# cards.gltf: one quad (x, y in [-1, 1], z = 0, facing +z, u along +x) drawn three times by
# three nodes: at z = 0 with a MASK material (alpha.png's alpha, alphaCutoff 0.4), at z = -1
# with a BLEND one (baseColorFactor alpha 0.25), at z = -2 opaque.
import base64
import json

pos = [-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0]
uv = [0, 1, 1, 1, 1, 0, 0, 0]
idx = [0, 1, 2, 0, 2, 3]
blob = struct.pack("<12f", *pos) + struct.pack("<8f", *uv) + struct.pack("<6H", *idx)
blob += b"\x00" * (-len(blob) % 4)
gltf = {
    "asset": {"version": "2.0"},
    "scene": 0,
    "scenes": [{"nodes": [0, 1, 2]}],
    "nodes": [{"mesh": 0}, {"mesh": 1, "translation": [0, 0, -1]},
              {"mesh": 2, "translation": [0, 0, -2]}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "indices": 2,
                                "material": m}]} for m in range(3)],
    "materials": [
        {"name": "card", "alphaMode": "MASK", "alphaCutoff": 0.4,
         "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "metallicFactor": 0}},
        {"name": "veil", "alphaMode": "BLEND",
         "pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 0.25], "metallicFactor": 0}},
        {"name": "wall", "pbrMetallicRoughness": {"metallicFactor": 0}},
    ],
    "textures": [{"source": 0, "sampler": 0}],
    "samplers": [{"magFilter": 9728, "minFilter": 9728}],
    "images": [{"uri": "alpha.png"}],
    "buffers": [{"byteLength": len(blob),
                 "uri": "data:application/octet-stream;base64," + base64.b64encode(blob).decode()}],
    "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 48},
                    {"buffer": 0, "byteOffset": 48, "byteLength": 32},
                    {"buffer": 0, "byteOffset": 80, "byteLength": 12}],
    "accessors": [
        {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
         "min": [-1, -1, 0], "max": [1, 1, 0]},
        {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC2"},
        {"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"},
    ],
}
with open("cards.gltf", "w") as f:
    json.dump(gltf, f, indent=1)
    f.write("\n")
