# The corpus's Blender scenes (issue 40, scenes/corpus/README.md): each modelled with
# Blender 3.4's Python API and written with Blender's own glTF 2.0 exporter
# (bpy.ops.export_scene.gltf, its defaults plus lights and cameras), as a user would. Where
# glTF has no word for what the scene needs (an HDR environment, a lens aperture), a drift
# .json beside the .glb adds it and names the .glb as its mesh.
#
#   blender -b --factory-startup -noaudio --python scripts/corpus/blender_corpus.py -- \
#       --out DIR --hdri DIR [--only NAME,NAME]
#
# writes DIR/NAME.glb (and DIR/NAME.json where a wrapper is needed) for each scene below.
# Blender is Z-up; the exporter turns it to glTF's +Y up: (x, y, z) -> (x, z, -y).
import argparse
import json
import math
import os
import sys

import bpy
from mathutils import Vector


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    p = argparse.ArgumentParser(prog="blender_corpus.py")
    p.add_argument("--out", required=True)
    p.add_argument("--hdri", required=True, help="the folder of the shared HDR panoramas")
    p.add_argument("--only", default="", help="comma-separated scene names (default: all)")
    return p.parse_args(argv)


def reset():
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.resolution_x, scene.render.resolution_y = 640, 480
    return scene


def material(name, base, roughness=0.8, metallic=0.0, emission=None, strength=1.0, image=None):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    nodes = m.node_tree.nodes
    bsdf = nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (*base, 1.0)
    bsdf.inputs["Metallic"].default_value = metallic
    bsdf.inputs["Roughness"].default_value = roughness
    if emission is not None:
        bsdf.inputs["Emission"].default_value = (*emission, 1.0)
        bsdf.inputs["Emission Strength"].default_value = strength
    if image is not None:
        tex = nodes.new("ShaderNodeTexImage")
        tex.image = image
        m.node_tree.links.new(tex.outputs["Color"], bsdf.inputs["Base Color"])
    return m


def add(op, name, mat, smooth=False, **kw):
    op(**kw)
    ob = bpy.context.object
    ob.name = name
    if smooth:
        bpy.ops.object.shade_smooth()
    ob.data.materials.append(mat)
    return ob


def aim(ob, location, target):
    ob.location = location
    ob.rotation_euler = (Vector(target) - Vector(location)).to_track_quat("-Z", "Y").to_euler()


def camera(location, target, lens=35.0):
    data = bpy.data.cameras.new("Camera")
    data.lens = lens
    ob = bpy.data.objects.new("Camera", data)
    bpy.context.scene.collection.objects.link(ob)
    aim(ob, location, target)
    bpy.context.scene.camera = ob
    return ob


def light(kind, name, location, energy, color=(1, 1, 1), target=None, size=None):
    data = bpy.data.lights.new(name, kind)
    data.energy = energy
    data.color = color
    if size is not None and kind == "SPOT":
        data.spot_size = size
    ob = bpy.data.objects.new(name, data)
    bpy.context.scene.collection.objects.link(ob)
    ob.location = location
    if target is not None:
        aim(ob, location, target)
    return ob


def room(w, d, h, mat, open_window=None):
    """A closed box room of w x d x h (floor at z = 0), normals inward. open_window: (x0, x1,
    z0, z1) cut out of the +y wall."""
    verts, faces = [], []

    def quad(a, b, c, e):
        i = len(verts)
        verts.extend([a, b, c, e])
        faces.append((i, i + 1, i + 2, i + 3))

    x, y = w / 2, d / 2
    quad((-x, -y, 0), (x, -y, 0), (x, y, 0), (-x, y, 0))  # floor, up
    quad((-x, -y, h), (-x, y, h), (x, y, h), (x, -y, h))  # ceiling, down
    quad((-x, -y, 0), (-x, y, 0), (-x, y, h), (-x, -y, h))  # -x wall
    quad((x, -y, 0), (x, -y, h), (x, y, h), (x, y, 0))  # +x wall
    quad((-x, -y, 0), (-x, -y, h), (x, -y, h), (x, -y, 0))  # -y wall
    if open_window is None:
        quad((-x, y, 0), (x, y, 0), (x, y, h), (-x, y, h))  # +y wall
    else:
        x0, x1, z0, z1 = open_window
        quad((-x, y, 0), (x, y, 0), (x, y, z0), (-x, y, z0))
        quad((-x, y, z1), (x, y, z1), (x, y, h), (-x, y, h))
        quad((-x, y, z0), (x0, y, z0), (x0, y, z1), (-x, y, z1))
        quad((x1, y, z0), (x, y, z0), (x, y, z1), (x1, y, z1))
    mesh = bpy.data.meshes.new("Room")
    mesh.from_pydata(verts, [], faces)
    ob = bpy.data.objects.new("Room", mesh)
    bpy.context.scene.collection.objects.link(ob)
    ob.data.materials.append(mat)
    return ob


def checker_image(out, name, n=256, cells=8):
    img = bpy.data.images.new(name, n, n)
    px = []
    for j in range(n):
        for i in range(n):
            c = ((i * cells // n) + (j * cells // n)) % 2
            v = (0.8, 0.75, 0.6) if c else (0.15, 0.25, 0.45)
            px.extend((*v, 1.0))
    img.pixels = px
    img.filepath_raw = os.path.join(out, name + ".png")
    img.file_format = "PNG"
    img.save()
    return img


# --- SCENES ---


def room_area(out):
    """A closed room lit by one area light: a 0.8 m emissive ceiling panel (glTF has no area
    lights; Blender exports an emissive mesh, which drift samples as triangle lights)."""
    room(5, 5, 3, material("Walls", (0.7, 0.7, 0.68)))
    add(bpy.ops.mesh.primitive_plane_add, "Panel",
        material("Panel", (0, 0, 0), emission=(1, 0.95, 0.85), strength=40.0),
        size=0.8, location=(0, 0, 2.99), rotation=(math.pi, 0, 0))
    add(bpy.ops.mesh.primitive_cube_add, "Box", material("Red", (0.7, 0.1, 0.08)), size=0.9,
        location=(-0.8, 0.4, 0.45), rotation=(0, 0, 0.4))
    add(bpy.ops.mesh.primitive_uv_sphere_add, "Ball", material("Green", (0.1, 0.5, 0.15), 0.4),
        True, radius=0.5, location=(0.9, -0.3, 0.5))
    camera((0, -2.4, 1.5), (0, 0.5, 0.9), 24)


def outdoor(out):
    """An open scene under an HDR panorama with a sun."""
    add(bpy.ops.mesh.primitive_plane_add, "Ground", material("Ground", (0.45, 0.42, 0.38)), size=60)
    for i, (x, y, s) in enumerate([(-2, 1, 1.0), (1.5, 2.5, 1.6), (3, -1, 0.7), (-4, 4, 2.0)]):
        add(bpy.ops.mesh.primitive_cube_add, "Block%d" % i, material("Stone%d" % i, (0.6, 0.55, 0.5)),
            size=s, location=(x, y, s / 2), rotation=(0, 0, 0.3 * i))
    add(bpy.ops.mesh.primitive_uv_sphere_add, "Ball", material("Ball", (0.7, 0.7, 0.72), 0.3), True,
        radius=0.8, location=(0, -1, 0.8))
    sun = light("SUN", "Sun", (0, 0, 10), 3.0)
    sun.rotation_euler = (math.radians(50), 0, math.radians(35))
    camera((0, -9, 2.5), (0, 1, 0.8), 35)
    return {"environment": {"map": "HDRI/sunset.exr", "multiplier": 1}}


def window(out):
    """An interior lit mostly indirectly: a sun through a window patch onto the floor, the
    rest of the room lit by its bounce and the sky."""
    room(6, 6, 3, material("Plaster", (0.75, 0.73, 0.7)), open_window=(-1.0, 1.0, 0.9, 2.4))
    add(bpy.ops.mesh.primitive_cube_add, "Table", material("Wood", (0.45, 0.3, 0.18), 0.6), size=1,
        location=(0.5, 0.5, 0.4), scale=(1.2, 0.7, 0.4))
    add(bpy.ops.mesh.primitive_cube_add, "Shelf", material("Shelf", (0.3, 0.35, 0.5)), size=1,
        location=(-2.5, -1, 1.0), scale=(0.4, 1.5, 1.0))
    sun = light("SUN", "Sun", (0, 10, 10), 6.0)
    sun.rotation_euler = (math.radians(-55), 0, math.radians(10))
    camera((1.5, -2.7, 1.6), (-0.5, 1.5, 0.8), 22)
    return {"environment": {"map": "HDRI/courtyard.exr", "multiplier": 0.5}}


def metals(out):
    """Metals and glossy dielectrics over a range of roughness, in a studio panorama."""
    add(bpy.ops.mesh.primitive_plane_add, "Floor", material("Floor", (0.5, 0.5, 0.5), 0.9), size=20)
    for i, r in enumerate([0.05, 0.15, 0.3, 0.5, 0.8]):
        x = -3.2 + 1.6 * i
        add(bpy.ops.mesh.primitive_uv_sphere_add, "Metal%d" % i,
            material("Gold%d" % i, (1.0, 0.77, 0.34), r, 1.0), True,
            radius=0.6, location=(x, 0, 0.6), segments=48, ring_count=24)
        add(bpy.ops.mesh.primitive_uv_sphere_add, "Plastic%d" % i,
            material("Plastic%d" % i, (0.1, 0.2, 0.6), r, 0.0), True,
            radius=0.4, location=(x, 1.6, 0.4), segments=32, ring_count=16)
    light("POINT", "Key", (2, -3, 4), 800.0)
    camera((0, -7, 2.6), (0, 0.6, 0.5), 40)
    return {"environment": {"map": "HDRI/studio.exr", "multiplier": 1}}


def textured(out):
    """A textured glTF as Blender exports it: an image texture on the ground and a box, a sun."""
    img = checker_image(out, "checker")
    add(bpy.ops.mesh.primitive_plane_add, "Ground", material("Checker", (1, 1, 1), 0.9, image=img),
        size=10)
    add(bpy.ops.mesh.primitive_cube_add, "Crate", material("Crate", (1, 1, 1), 0.7, image=img),
        size=1.2, location=(0.5, 0.5, 0.6), rotation=(0, 0, 0.5))
    add(bpy.ops.mesh.primitive_uv_sphere_add, "Ball", material("Orange", (0.9, 0.4, 0.1), 0.35),
        True, radius=0.6, location=(-1.3, -0.3, 0.6))
    sun = light("SUN", "Sun", (0, 0, 10), 1.0)
    sun.rotation_euler = (math.radians(40), 0, math.radians(-30))
    camera((0, -6, 3), (0, 0.3, 0.4), 35)


def dof(out):
    """Strong depth of field: a row of objects receding from the lens, focused on the third."""
    add(bpy.ops.mesh.primitive_plane_add, "Floor", material("Floor", (0.6, 0.6, 0.6)), size=40)
    for i in range(7):
        add(bpy.ops.mesh.primitive_cylinder_add, "Post%d" % i,
            material("Post%d" % i, (0.2 + 0.1 * i, 0.5, 0.8 - 0.1 * i), 0.5), True,
            radius=0.25, depth=1.6, location=(0.6 * (-1) ** i, 1.5 * i, 0.8))
    sun = light("SUN", "Sun", (0, 0, 10), 3.0)
    sun.rotation_euler = (math.radians(35), 0, math.radians(60))
    camera((0, -3, 1.0), (0, 6, 0.8), 50)
    # The lens: glTF cameras have no aperture. Focus on post 2 (6 m away), a 30 cm lens.
    return {"camera_lens": {"aperture_radius": 0.15, "focus_distance": 6.0},
            "environment": {"color": [0.4, 0.45, 0.55]}}


def many_lights(out):
    """Many small lights: 32 coloured point lamps over a floor of objects, no other light."""
    room(12, 12, 4, material("Walls", (0.6, 0.6, 0.6)))
    for i in range(6):
        add(bpy.ops.mesh.primitive_cube_add, "Block%d" % i, material("Block%d" % i, (0.6, 0.6, 0.55)),
            size=0.8, location=(-4 + 1.6 * i, 0.5 * (-1) ** i, 0.4))
    for i in range(32):
        a = 2 * math.pi * i / 32
        hue = i / 32.0
        color = (0.5 + 0.5 * math.cos(2 * math.pi * hue), 0.5 + 0.5 * math.cos(2 * math.pi * (hue - 1 / 3)),
                 0.5 + 0.5 * math.cos(2 * math.pi * (hue - 2 / 3)))
        light("POINT", "Lamp%d" % i, (4.5 * math.cos(a), 4.5 * math.sin(a), 0.3 + 0.1 * (i % 5)), 40.0,
              color)
    camera((0, -5.5, 3.2), (0, 0.5, 0.2), 24)


def emissive(out):
    """Emissive meshes as the only light: two neon tubes and a glowing sphere in a dark room."""
    room(6, 6, 3, material("Walls", (0.65, 0.65, 0.65)))
    add(bpy.ops.mesh.primitive_cylinder_add, "TubeA",
        material("NeonA", (0, 0, 0), emission=(1.0, 0.2, 0.6), strength=30.0), radius=0.04, depth=3,
        location=(-1.5, 1.5, 2.2), rotation=(0, math.pi / 2, 0))
    add(bpy.ops.mesh.primitive_cylinder_add, "TubeB",
        material("NeonB", (0, 0, 0), emission=(0.2, 0.7, 1.0), strength=30.0), radius=0.04, depth=3,
        location=(1.8, 0, 1.0), rotation=(math.pi / 2, 0, 0))
    add(bpy.ops.mesh.primitive_uv_sphere_add, "Glow",
        material("Glow", (0, 0, 0), emission=(1.0, 0.8, 0.4), strength=15.0), True,
        radius=0.25, location=(-0.5, -0.5, 0.25), segments=16, ring_count=8)
    add(bpy.ops.mesh.primitive_cube_add, "Plinth", material("Plinth", (0.5, 0.5, 0.55), 0.5),
        size=0.8, location=(0.5, 0.8, 0.4))
    camera((0, -2.8, 1.4), (0, 1, 1.0), 24)


def night(out):
    """A night scene with one bright source: a street lamp (spot) over a ground with houses,
    under a dim night sky."""
    add(bpy.ops.mesh.primitive_plane_add, "Street", material("Asphalt", (0.2, 0.2, 0.2), 0.7),
        size=60)
    for i, x in enumerate([-6, 0, 6]):
        add(bpy.ops.mesh.primitive_cube_add, "House%d" % i, material("House%d" % i, (0.6, 0.5, 0.4)),
            size=1, location=(x, 8, 2), scale=(2, 2, 2))
    pole = material("Pole", (0.3, 0.3, 0.3), 0.4)
    add(bpy.ops.mesh.primitive_cylinder_add, "Pole", pole, radius=0.08, depth=5,
        location=(1.5, 2, 2.5))
    # The lamp hangs from an arm, 0.6 m off the pole: inside the pole (as until 2026-12-07) its
    # light never left the cylinder, and the path tracer saw only the sky.
    add(bpy.ops.mesh.primitive_cube_add, "Arm", pole, size=1, location=(1.5, 1.7, 4.95),
        scale=(0.04, 0.34, 0.04))
    light("SPOT", "StreetLamp", (1.5, 1.4, 4.8), 20000.0, (1.0, 0.8, 0.5), target=(1.0, 1.5, 0),
          size=math.radians(110))
    camera((-3, -9, 2.0), (1, 3, 1.2), 30)
    return {"environment": {"map": "HDRI/night.exr", "multiplier": 0.15}}


SCENES = {
    "bl-room-area": room_area,
    "bl-outdoor-sun": outdoor,
    "bl-window": window,
    "bl-metals": metals,
    "bl-textured": textured,
    "bl-dof": dof,
    "bl-many-lights": many_lights,
    "bl-emissive": emissive,
    "bl-night": night,
}


def to_gltf(v):
    return [v[0], v[2], -v[1]]


def wrapper(name, extra, cam, hdri):
    """The drift .json beside NAME.glb: the environment and lens glTF cannot carry."""
    loc = cam.matrix_world.translation
    fwd = cam.matrix_world.to_3x3() @ Vector((0, 0, -1))
    up = cam.matrix_world.to_3x3() @ Vector((0, 1, 0))
    sx, sy = bpy.context.scene.render.resolution_x, bpy.context.scene.render.resolution_y
    fov_x = cam.data.angle_x
    fov_y = 2 * math.atan(math.tan(fov_x / 2) * sy / sx)
    camera_json = {"position": to_gltf(loc), "target": to_gltf(loc + fwd), "up": to_gltf(up),
                   "fov_y": math.degrees(fov_y), "width": sx, "height": sy}
    camera_json.update(extra.get("camera_lens", {}))
    env = dict(extra.get("environment", {}))
    if "map" in env:
        env["map"] = env["map"].replace("HDRI", hdri)
    doc = {"comment": "Blender 3.4 corpus scene %s (scripts/corpus/blender_corpus.py): the .glb as "
           "Blender's glTF exporter wrote it, plus what glTF cannot say." % name,
           "version": 1, "camera": camera_json, "meshes": [{"path": name + ".glb"}]}
    if env:
        doc["environment"] = env
    return doc


def main():
    args = parse_args()
    os.makedirs(args.out, exist_ok=True)
    only = [s for s in args.only.split(",") if s]
    for name, build in SCENES.items():
        if only and name not in only:
            continue
        reset()
        extra = build(args.out) or {}
        # The textured scene as "glTF Separate" (.gltf + .bin + its images beside): drift reads
        # no images embedded in a .glb's buffer yet.
        fmt = "GLTF_SEPARATE" if name == "bl-textured" else "GLB"
        path = os.path.join(args.out, name + (".gltf" if fmt == "GLTF_SEPARATE" else ".glb"))
        bpy.ops.export_scene.gltf(filepath=path, export_format=fmt, export_lights=True,
                                  export_cameras=True)
        if extra:
            hdri = os.path.relpath(args.hdri, args.out)
            doc = wrapper(name, extra, bpy.context.scene.camera, hdri)
            with open(os.path.join(args.out, name + ".json"), "w") as f:
                json.dump(doc, f, indent=1)
        print("corpus: wrote", path)


main()
