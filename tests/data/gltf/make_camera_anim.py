#!/usr/bin/env python3
"""Writes the small glTF files with camera animations that tests/unit/test_gltf_anim.c and
tests/cli/test_gltf_animation.sh read (run from this folder: python3 make_camera_anim.py).

Every file holds a floor quad, a tilted quad and a camera; its buffer is one base64 data URI.
  camera_linear.gltf   a parent "rig" turning 0 -> 90 degrees about +y (LINEAR: slerp) over
                       1 s, the camera below it moving (0, 1, 5) -> (2, 1, 5) (LINEAR), 24 fps
  camera_step_cubic.gltf  the camera's translation a CUBICSPLINE over [0, 2] s and its
                       rotation STEP (identity, then 90 degrees about +y from 0.5 s)
  camera_step_cubic.glb  the same as a binary glTF (its buffer in the BIN chunk)
  mesh_anim.gltf       camera_linear plus a translation channel on the tilted quad's node
                       (the wall rises (0, 0, 0) -> (0, 1, 0) over 1 s, LINEAR)
  mesh_moved.gltf      camera_linear with the wall standing where mesh_anim.gltf's is at
                       t = 0.5 s (translation (0, 0.5, 0)), no animation of it: the static twin
The unit test computes the same cameras in closed form from the numbers below.
"""
import base64
import json
import math
import struct


def f32(values):
    return struct.pack("<%df" % len(values), *values)


class Builder:
    def __init__(self):
        self.data = bytearray()
        self.views = []
        self.accessors = []

    def add(self, values, type_, count, extra=None):
        while len(self.data) % 4:
            self.data.append(0)
        offset = len(self.data)
        blob = f32(values)
        self.data += blob
        self.views.append({"buffer": 0, "byteOffset": offset, "byteLength": len(blob)})
        acc = {"bufferView": len(self.views) - 1, "componentType": 5126, "count": count,
               "type": type_}
        acc.update(extra or {})
        self.accessors.append(acc)
        return len(self.accessors) - 1

    def add_u16(self, values):
        while len(self.data) % 4:
            self.data.append(0)
        offset = len(self.data)
        blob = struct.pack("<%dH" % len(values), *values)
        self.data += blob
        self.views.append({"buffer": 0, "byteOffset": offset, "byteLength": len(blob)})
        self.accessors.append({"bufferView": len(self.views) - 1, "componentType": 5123,
                               "count": len(values), "type": "SCALAR"})
        return len(self.accessors) - 1


def quat_y(degrees):
    h = math.radians(degrees) / 2
    return [0.0, math.sin(h), 0.0, math.cos(h)]


def scene(kind):
    b = Builder()
    floor = [-4, 0, -4, 4, 0, -4, 4, 0, 4, -4, 0, 4]
    wall = [-1, 0, -1, 1, 0, -1, 1, 2, -1.5, -1, 2, -1.5]
    meshes = []
    for quad in (floor, wall):
        pos = b.add(quad, "VEC3", 4, {"min": [min(quad[i::3]) for i in range(3)],
                                       "max": [max(quad[i::3]) for i in range(3)]})
        idx = b.add_u16([0, 2, 1, 0, 3, 2])
        meshes.append({"primitives": [{"attributes": {"POSITION": pos}, "indices": idx,
                                       "material": len(meshes)}]})
    materials = [{"name": "floor", "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.8, 0.8, 1],
                                                            "metallicFactor": 0}},
                 {"name": "wall", "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.2, 0.1, 1],
                                                           "metallicFactor": 0}}]
    nodes = [{"name": "floor", "mesh": 0}, {"name": "wall", "mesh": 1}]
    if kind == "mesh_moved":
        nodes[1]["translation"] = [0, 0.5, 0]
    samplers, channels = [], []

    def channel(node, path, times, values, type_, interp):
        t = b.add(times, "SCALAR", len(times), {"min": [min(times)], "max": [max(times)]})
        v = b.add(values, type_, len(values) // (4 if type_ == "VEC4" else 3))
        samplers.append({"input": t, "output": v, "interpolation": interp})
        channels.append({"sampler": len(samplers) - 1, "target": {"node": node, "path": path}})

    if kind in ("linear", "mesh", "mesh_moved"):
        nodes.append({"name": "rig", "children": [3]})
        nodes.append({"name": "Camera", "camera": 0, "translation": [0, 1, 5]})
        channel(2, "rotation", [0.0, 1.0], quat_y(0) + quat_y(90), "VEC4", "LINEAR")
        channel(3, "translation", [0.0, 1.0], [0, 1, 5, 2, 1, 5], "VEC3", "LINEAR")
        if kind == "mesh":
            channel(1, "translation", [0.0, 1.0], [0, 0, 0, 0, 1, 0], "VEC3", "LINEAR")
    else:
        nodes.append({"name": "Camera", "camera": 0, "translation": [0, 1, 5]})
        # in-tangent, value, out-tangent per key
        channel(2, "translation", [0.0, 2.0],
                [0, 0, 0, 0, 1, 5, 3, 0, 0,
                 0, 0, -1, 1, 1, 6, 0, 0, 0], "VEC3", "CUBICSPLINE")
        channel(2, "rotation", [0.0, 0.5], quat_y(0) + quat_y(90), "VEC4", "STEP")
    roots = [0, 1, 2]
    gltf = {
        "asset": {"version": "2.0", "generator": "drift tests/data/gltf/make_camera_anim.py"},
        "scene": 0,
        "scenes": [{"nodes": roots}],
        "nodes": nodes,
        "cameras": [{"name": "Camera", "type": "perspective",
                     "perspective": {"yfov": math.radians(50), "aspectRatio": 1.0,
                                     "znear": 0.1, "zfar": 100}}],
        "meshes": meshes,
        "materials": materials,
        "animations": [{"name": "CameraAction", "channels": channels, "samplers": samplers}],
        "buffers": [{"byteLength": len(b.data),
                     "uri": "data:application/octet-stream;base64," +
                            base64.b64encode(bytes(b.data)).decode()}],
        "bufferViews": b.views,
        "accessors": b.accessors,
    }
    return gltf


def write_glb(gltf, path):
    """The same scene as a binary glTF: the buffer moves into the BIN chunk."""
    uri = gltf["buffers"][0].pop("uri")
    data = base64.b64decode(uri.split(",", 1)[1])
    text = json.dumps(gltf).encode()
    text += b" " * (-len(text) % 4)
    data += b"\0" * (-len(data) % 4)
    body = struct.pack("<I4s", len(text), b"JSON") + text + struct.pack("<I4s", len(data), b"BIN\0") + data
    with open(path, "wb") as f:
        f.write(struct.pack("<4sII", b"glTF", 2, 12 + len(body)) + body)


write_glb(scene("step_cubic"), "camera_step_cubic.glb")
for name, kind in (("camera_linear", "linear"), ("camera_step_cubic", "step_cubic"),
                   ("mesh_anim", "mesh"), ("mesh_moved", "mesh_moved")):
    with open(name + ".gltf", "w") as f:
        json.dump(scene(kind), f, indent=1)
        f.write("\n")
