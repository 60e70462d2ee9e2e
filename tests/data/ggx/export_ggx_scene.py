# Builds issue 41's GGX scene in Blender and writes it with Blender's own glTF exporter:
# four gold-coloured metal spheres of roughness 0.05, 0.25, 0.5 and 0.8, a glass sphere
# (Principled transmission 1, IOR 1.5), a grey floor, an emissive panel the metals reflect and
# a point light. tests/data/ggx/make_reference.sh runs it and renders the Cycles reference:
#
#   blender -b --factory-startup -noaudio --python tests/data/ggx/export_ggx_scene.py -- --out DIR
#
# writes DIR/ggx_scene.glb. With --textured: DIR/ggx_scene.gltf (+ .bin and two texture
# images beside it: drift reads glTF textures from image files) where the floor carries a
# metallic-roughness texture (a checker of metal / plastic and roughness 0.3 / 0.8) and a back
# wall a tangent-space normal map (ridges).
import argparse
import os
import sys

import bpy
from mathutils import Vector


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    p = argparse.ArgumentParser(prog="export_ggx_scene.py")
    p.add_argument("--out", required=True)
    p.add_argument("--textured", action="store_true")
    p.add_argument("--no-spheres", action="store_true",
                   help="leave the metal and glass spheres out (the textured test's scene: "
                        "their point-light highlights and caustics are sub-pixel and converge "
                        "slowly in both renderers)")
    return p.parse_args(argv)


def material(name, base, roughness, metallic=0.0, transmission=0.0, emission=None, strength=1.0):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    bsdf = m.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (*base, 1.0)
    bsdf.inputs["Metallic"].default_value = metallic
    bsdf.inputs["Roughness"].default_value = roughness
    bsdf.inputs["Transmission"].default_value = transmission
    bsdf.inputs["IOR"].default_value = 1.5
    if emission is not None:
        bsdf.inputs["Emission"].default_value = (*emission, 1.0)
        bsdf.inputs["Emission Strength"].default_value = strength
    return m


def place(ob, location, target=None):
    ob.location = location
    if target is not None:
        ob.rotation_euler = (Vector(target) - Vector(location)).to_track_quat("-Z", "Y").to_euler()


def image(name, size, texel, out_dir):
    img = bpy.data.images.new(name, size, size, alpha=False, float_buffer=False)
    img.colorspace_settings.name = "Non-Color"
    px = []
    for y in range(size):
        for x in range(size):
            px.extend((*texel(x, y), 1.0))
    img.pixels = px
    img.filepath_raw = os.path.join(out_dir, name + ".png")
    img.file_format = "PNG"
    img.save()
    return img


def checker(x, y):
    # B = metallic, G = roughness: 8 x 8 checker squares of metal (rough 0.3) and plastic
    # (rough 0.8).
    metal = ((x // 8) + (y // 8)) % 2 == 0
    return (0.0, 0.3 if metal else 0.8, 1.0 if metal else 0.0)


def write_png(path, size, texel):
    # Blender 3.4's exporter re-composes a metallic-roughness image from Separate RGB links
    # and writes it blank (R = 1, G = B = 0); the file it refers to is rewritten here.
    import struct
    import zlib
    rows = b"".join(b"\x00" + bytes(int(round(255 * c)) for x in range(size)
                                     for c in texel(x, size - 1 - y)) for y in range(size))
    def chunk(tag, data):
        return (struct.pack(">I", len(data)) + tag + data +
                struct.pack(">I", zlib.crc32(tag + data) & 0xFFFFFFFF))
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", size, size, 8, 2, 0, 0, 0))
                + chunk(b"IDAT", zlib.compress(rows)) + chunk(b"IEND", b""))


def textured_floor(out_dir):
    # B = metallic, G = roughness: 8 x 8 checker squares of gold metal (rough 0.3) and
    # plastic (rough 0.8).
    img = image("floor_mr", 64, checker, out_dir)
    m = material("Floor", (0.8, 0.7, 0.5), 1.0, metallic=1.0)
    nodes, links = m.node_tree.nodes, m.node_tree.links
    tex = nodes.new("ShaderNodeTexImage")
    tex.image = img
    sep = nodes.new("ShaderNodeSeparateRGB")
    links.new(tex.outputs["Color"], sep.inputs["Image"])
    bsdf = nodes["Principled BSDF"]
    links.new(sep.outputs["B"], bsdf.inputs["Metallic"])
    links.new(sep.outputs["G"], bsdf.inputs["Roughness"])
    return m


def bumpy_wall(out_dir):
    # Ridges along u: the normal tilts +-0.6 rad about v, as a sine of u.
    import math
    def texel(x, y):
        a = 0.6 * math.sin(2.0 * math.pi * x / 16.0)
        return (0.5 + 0.5 * math.sin(a), 0.5, 0.5 + 0.5 * math.cos(a))
    img = image("wall_normal", 64, texel, out_dir)
    m = material("Wall", (0.5, 0.6, 0.7), 0.35)
    nodes, links = m.node_tree.nodes, m.node_tree.links
    tex = nodes.new("ShaderNodeTexImage")
    tex.image = img
    nmap = nodes.new("ShaderNodeNormalMap")
    links.new(tex.outputs["Color"], nmap.inputs["Color"])
    links.new(nmap.outputs["Normal"], nodes["Principled BSDF"].inputs["Normal"])
    return m


def sphere(name, x, mat):
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.5, segments=48, ring_count=24, location=(x, 0, 0.5))
    bpy.context.object.name = name
    bpy.ops.object.shade_smooth()
    bpy.context.object.data.materials.append(mat)


def main():
    args = parse_args()
    for ob in list(bpy.data.objects):
        bpy.data.objects.remove(ob, do_unlink=True)
    for coll in (bpy.data.meshes, bpy.data.cameras, bpy.data.lights, bpy.data.materials):
        for block in list(coll):
            coll.remove(block)
    scene = bpy.context.scene

    os.makedirs(args.out, exist_ok=True)
    bpy.ops.mesh.primitive_plane_add(size=12.0, location=(0, 0, 0))
    bpy.context.object.name = "Floor"
    if args.textured:
        bpy.context.object.data.materials.append(textured_floor(args.out))
    else:
        bpy.context.object.data.materials.append(material("Floor", (0.6, 0.6, 0.6), 0.7))

    # The back wall, 8 m x 3 m, facing the camera (-Y), normal-mapped.
    if args.textured:
        bpy.ops.mesh.primitive_plane_add(size=1.0, location=(0.0, 2.0, 1.5))
        wall = bpy.context.object
        wall.name = "Wall"
        wall.scale = (8.0, 3.0, 1.0)
        wall.rotation_euler = (1.5707963, 0.0, 0.0)
        # The scale goes into the vertices: with the object's own non-uniform scale Cycles
        # applies the normal map in object space and the normal transform then shrinks the
        # tilts along x by 8, where glTF (and drift) bend the normal in world space.
        bpy.ops.object.transform_apply(location=False, rotation=False, scale=True)
        wall.data.materials.append(bumpy_wall(args.out))

    gold = (1.0, 0.78, 0.34)
    for i, r in enumerate(() if args.no_spheres else (0.05, 0.25, 0.5, 0.8)):
        sphere("Metal%d" % i, -2.4 + 1.2 * i, material("Metal%d" % i, gold, r, metallic=1.0))
    if not args.no_spheres:
        sphere("Glass", 2.4, material("Glass", (1.0, 1.0, 1.0), 0.0, transmission=1.0))

    # A 4 m x 2 m emissive slab above the camera's line of sight, facing the spheres: a closed
    # box, since Cycles' emission is two-sided and drift's leaves the front faces only.
    bpy.ops.mesh.primitive_cube_add(size=1.0, location=(0.0, -4.0, 3.0))
    panel = bpy.context.object
    panel.name = "Panel"
    panel.scale = (4.0, 2.0, 0.05)
    panel.rotation_euler = (Vector((0, 0, 0.5)) - Vector((0.0, -4.0, 3.0))).to_track_quat("Z", "Y").to_euler()
    panel.data.materials.append(
        material("Panel", (0.0, 0.0, 0.0), 1.0, emission=(1.0, 0.95, 0.9), strength=3.0))

    point = bpy.data.lights.new("Point", "POINT")
    point.energy = 500.0
    ob = bpy.data.objects.new("Point", point)
    scene.collection.objects.link(ob)
    place(ob, (2.0, -2.0, 4.0))

    cam = bpy.data.cameras.new("Camera")
    cam.sensor_fit = "VERTICAL"
    cam.angle_y = 0.45
    ob = bpy.data.objects.new("Camera", cam)
    scene.collection.objects.link(ob)
    place(ob, (0.0, -8.0, 2.2), target=(0.0, 0.0, 0.5))
    scene.camera = ob

    # The panel is a mesh: its scale and rotation are applied by the exporter's node transform.
    if args.textured:
        bpy.ops.export_scene.gltf(filepath=os.path.join(args.out, "ggx_scene.gltf"),
                                  export_format="GLTF_SEPARATE", export_cameras=True,
                                  export_lights=True)
        write_png(os.path.join(args.out, "floor_mr.png"), 64, checker)
    else:
        bpy.ops.export_scene.gltf(filepath=os.path.join(args.out, "ggx_scene.glb"),
                                  export_format="GLB", export_cameras=True, export_lights=True)
    print("EXPORTED", args.out)


main()
