#!/usr/bin/env python3
# Writes blender_scene.gltf: the scene of issue 22 (a plane, a red sphere of roughness 0.3, a
# cube, a 1000 W point light, an 800 W spot light, an emissive panel, a camera) laid out as
# Blender 3.4's glTF 2.0 exporter writes it ("glTF Embedded", +Y up, lighting mode "Standard"):
# light intensities in candela = W * 683 / (4 pi), spot cone = spot_size / 2 with the inner
# angle = outer * (1 - blend), emissive strength > 1 through KHR_materials_emissive_strength,
# Principled BSDF as pbrMetallicRoughness, the camera's yfov from sensor fit. Kept as the
# hand-written stand-in for a real export where Blender is not installed (see README.md).
import base64, json, math, struct, sys

buf = bytearray()
views, accessors = [], []


def add(data, fmt, count, typ, comp, target, minmax=None):
    while len(buf) % 4:
        buf.append(0)
    off = len(buf)
    buf.extend(struct.pack("<%d%s" % (len(data), fmt), *data))
    views.append({"buffer": 0, "byteOffset": off, "byteLength": len(buf) - off, "target": target})
    a = {"bufferView": len(views) - 1, "componentType": comp, "count": count, "type": typ}
    if minmax:
        a["min"], a["max"] = minmax
    accessors.append(a)
    return len(accessors) - 1


def mesh(name, pos, nrm, idx, material):
    p = add([c for v in pos for c in v], "f", len(pos), "VEC3", 5126, 34962,
            ([min(v[k] for v in pos) for k in range(3)], [max(v[k] for v in pos) for k in range(3)]))
    n = add([c for v in nrm for c in v], "f", len(nrm), "VEC3", 5126, 34962)
    i = add(idx, "H", len(idx), "SCALAR", 5123, 34963)
    return {"name": name, "primitives": [{"attributes": {"POSITION": p, "NORMAL": n},
                                          "indices": i, "material": material}]}


def plane(half):
    pos = [(-half, 0, half), (half, 0, half), (half, 0, -half), (-half, 0, -half)]
    return pos, [(0, 1, 0)] * 4, [0, 1, 2, 0, 2, 3]


def cube(half):
    pos, nrm, idx = [], [], []
    for axis in range(3):
        for sign in (1, -1):
            n = [0, 0, 0]
            n[axis] = sign
            u, v = [0, 0, 0], [0, 0, 0]
            u[(axis + 1) % 3] = 1
            v[(axis + 2) % 3] = 1
            base = len(pos)
            for a, b in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
                pos.append(tuple(half * (n[k] + a * u[k] + b * v[k]) for k in range(3)))
                nrm.append(tuple(n))
            quad = [0, 1, 2, 0, 2, 3] if sign > 0 else [0, 2, 1, 0, 3, 2]
            idx += [base + q for q in quad]
    return pos, nrm, idx


def sphere(r, segments=32, rings=16):
    pos, nrm, idx = [], [], []
    for j in range(rings + 1):
        t = math.pi * j / rings
        for i in range(segments + 1):
            p = 2 * math.pi * i / segments
            n = (math.sin(t) * math.cos(p), math.cos(t), -math.sin(t) * math.sin(p))
            nrm.append(n)
            pos.append(tuple(r * c for c in n))
    for j in range(rings):
        for i in range(segments):
            a, b = j * (segments + 1) + i, (j + 1) * (segments + 1) + i
            # Triangle fans at the poles, as Blender's UV sphere has (no zero-area triangles).
            idx += ([a, b, a + 1] if j > 0 else []) + ([a + 1, b, b + 1] if j < rings - 1 else [])
    return pos, nrm, idx


def look_rotation(eye, target):
    # Quaternion turning -Z to (target - eye) with +Y up, as the exporter writes node rotations.
    f = [t - e for t, e in zip(target, eye)]
    l = math.sqrt(sum(c * c for c in f))
    f = [c / l for c in f]
    z = [-c for c in f]
    x = [z[2], 0, -z[0]]  # up × z with up = +Y
    l = math.sqrt(sum(c * c for c in x))
    x = [c / l for c in x]
    y = [z[1] * x[2] - z[2] * x[1], z[2] * x[0] - z[0] * x[2], z[0] * x[1] - z[1] * x[0]]
    m = [[x[0], y[0], z[0]], [x[1], y[1], z[1]], [x[2], y[2], z[2]]]
    w = math.sqrt(max(0.0, 1 + m[0][0] + m[1][1] + m[2][2])) / 2
    return [(m[2][1] - m[1][2]) / (4 * w), (m[0][2] - m[2][0]) / (4 * w),
            (m[1][0] - m[0][1]) / (4 * w), w]


W_TO_CD = 683 / (4 * math.pi)
spot_size, spot_blend = math.radians(60), 0.15
materials = [
    {"name": "Floor", "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.8, 0.8, 1],
                                               "metallicFactor": 0, "roughnessFactor": 1}},
    {"name": "Red", "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.05, 0.05, 1],
                                             "metallicFactor": 0, "roughnessFactor": 0.3}},
    {"name": "Grey", "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1],
                                              "metallicFactor": 0, "roughnessFactor": 0.6}},
    {"name": "Panel", "emissiveFactor": [1, 0.9, 0.7],
     "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 4}},
     "pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1], "metallicFactor": 0,
                              "roughnessFactor": 1}},
]
meshes = [mesh("Plane", *plane(5), 0), mesh("Sphere", *sphere(1), 1), mesh("Cube", *cube(0.5), 2),
          mesh("Panel", *plane(0.4), 3)]
cam_eye, spot_eye = [0, 3, 9], [-3, 5, 0]
doc = {
    "asset": {"generator": "Khronos glTF Blender I/O v3.4.50 (layout; written by "
                           "tests/data/gltf/make_blender_scene.py)", "version": "2.0"},
    "extensionsUsed": ["KHR_lights_punctual", "KHR_materials_emissive_strength"],
    "extensions": {"KHR_lights_punctual": {"lights": [
        {"color": [1, 1, 1], "intensity": 1000 * W_TO_CD, "type": "point", "name": "Point"},
        {"color": [1, 0.95, 0.9], "intensity": 800 * W_TO_CD, "type": "spot", "name": "Spot",
         "spot": {"outerConeAngle": spot_size / 2,
                  "innerConeAngle": spot_size / 2 - spot_size / 2 * spot_blend}}]}},
    "scene": 0,
    "scenes": [{"name": "Scene", "nodes": [0, 1, 2, 3, 4, 5, 6]}],
    "nodes": [
        {"name": "Plane", "mesh": 0},
        {"name": "Sphere", "mesh": 1, "translation": [0, 1, 0]},
        {"name": "Cube", "mesh": 2, "translation": [2.5, 0.5, -1],
         "rotation": [0, math.sin(math.radians(20)), 0, math.cos(math.radians(20))]},
        {"name": "Panel", "mesh": 3, "translation": [-2.5, 1.2, -2],
         "rotation": [math.sin(math.radians(45)), 0, 0, math.cos(math.radians(45))]},
        {"name": "Point", "translation": [1.5, 4, 3],
         "extensions": {"KHR_lights_punctual": {"light": 0}}},
        {"name": "Spot", "translation": spot_eye, "rotation": look_rotation(spot_eye, [0, 0, 0]),
         "extensions": {"KHR_lights_punctual": {"light": 1}}},
        {"name": "Camera", "camera": 0, "translation": cam_eye,
         "rotation": look_rotation(cam_eye, [0, 0.8, 0])},
    ],
    "cameras": [{"name": "Camera", "type": "perspective",
                 "perspective": {"aspectRatio": 4 / 3, "yfov": 0.6, "zfar": 100, "znear": 0.1}}],
    "materials": materials,
    "meshes": meshes,
    "accessors": accessors,
    "bufferViews": views,
    "buffers": [{"byteLength": len(buf), "uri": "data:application/octet-stream;base64," +
                 base64.b64encode(bytes(buf)).decode()}],
}
out = sys.argv[1] if len(sys.argv) > 1 else "blender_scene.gltf"
with open(out, "w") as f:
    json.dump(doc, f, indent=1)
    f.write("\n")
