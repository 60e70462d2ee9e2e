# Builds issue 41's GGX scene in Blender and writes it with Blender's own glTF exporter:
# four gold-coloured metal spheres of roughness 0.05, 0.25, 0.5 and 0.8, a glass sphere
# (Principled transmission 1, IOR 1.5), a grey floor, an emissive panel the metals reflect and
# a point light. tests/data/ggx/make_reference.sh runs it and renders the Cycles reference:
#
#   blender -b --factory-startup -noaudio --python tests/data/ggx/export_ggx_scene.py -- --out DIR
#
# writes DIR/ggx_scene.glb. Textured objects (metallic-roughness, normal map) are not in it:
# drift does not read those textures yet (docs/materials.md).
import argparse
import os
import sys

import bpy
from mathutils import Vector


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    p = argparse.ArgumentParser(prog="export_ggx_scene.py")
    p.add_argument("--out", required=True)
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

    bpy.ops.mesh.primitive_plane_add(size=12.0, location=(0, 0, 0))
    bpy.context.object.name = "Floor"
    bpy.context.object.data.materials.append(material("Floor", (0.6, 0.6, 0.6), 0.7))

    gold = (1.0, 0.78, 0.34)
    for i, r in enumerate((0.05, 0.25, 0.5, 0.8)):
        sphere("Metal%d" % i, -2.4 + 1.2 * i, material("Metal%d" % i, gold, r, metallic=1.0))
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

    os.makedirs(args.out, exist_ok=True)
    # The panel is a mesh: its scale and rotation are applied by the exporter's node transform.
    bpy.ops.export_scene.gltf(filepath=os.path.join(args.out, "ggx_scene.glb"),
                              export_format="GLB", export_cameras=True, export_lights=True)
    print("EXPORTED", args.out)


main()
