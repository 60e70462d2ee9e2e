# Builds issue 41's clearcoat scene in Blender and writes it with Blender's own glTF exporter
# (KHR_materials_clearcoat): four spheres in a row, from the left a red diffuse base without a
# coat, the same red under a coat of roughness 0.05, under a coat of roughness 0.3, and a gold
# metal of roughness 0.5 under a coat of roughness 0.05 (clearcoat 1 on the coated three); a
# grey floor, an emissive panel the coats reflect and a point light, as
# tests/data/ggx/export_ggx_scene.py. tests/data/clearcoat/make_reference.sh runs it and
# renders the Cycles reference:
#
#   blender -b --factory-startup -noaudio --python tests/data/clearcoat/export_clearcoat_scene.py -- --out DIR
#
# writes DIR/clearcoat_scene.glb.
import argparse
import os
import sys

import bpy
from mathutils import Vector


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    p = argparse.ArgumentParser(prog="export_clearcoat_scene.py")
    p.add_argument("--out", required=True)
    return p.parse_args(argv)


def material(name, base, roughness, metallic=0.0, clearcoat=0.0, clearcoat_roughness=0.03,
             emission=None, strength=1.0):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    bsdf = m.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (*base, 1.0)
    bsdf.inputs["Metallic"].default_value = metallic
    bsdf.inputs["Roughness"].default_value = roughness
    bsdf.inputs["IOR"].default_value = 1.5
    bsdf.inputs["Clearcoat"].default_value = clearcoat
    bsdf.inputs["Clearcoat Roughness"].default_value = clearcoat_roughness
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
    os.makedirs(args.out, exist_ok=True)

    bpy.ops.mesh.primitive_plane_add(size=12.0, location=(0, 0, 0))
    bpy.context.object.name = "Floor"
    bpy.context.object.data.materials.append(material("Floor", (0.6, 0.6, 0.6), 0.7))

    red, gold = (0.7, 0.08, 0.06), (1.0, 0.78, 0.34)
    sphere("Bare", -1.8, material("Bare", red, 0.5))
    sphere("Coat005", -0.6, material("Coat005", red, 0.5, clearcoat=1.0, clearcoat_roughness=0.05))
    sphere("Coat03", 0.6, material("Coat03", red, 0.5, clearcoat=1.0, clearcoat_roughness=0.3))
    sphere("MetalCoat", 1.8,
           material("MetalCoat", gold, 0.5, metallic=1.0, clearcoat=1.0, clearcoat_roughness=0.05))

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
    cam.angle_y = 0.4
    ob = bpy.data.objects.new("Camera", cam)
    scene.collection.objects.link(ob)
    place(ob, (0.0, -8.0, 2.2), target=(0.0, 0.0, 0.5))
    scene.camera = ob

    bpy.ops.export_scene.gltf(filepath=os.path.join(args.out, "clearcoat_scene.glb"),
                              export_format="GLB", export_cameras=True, export_lights=True)
    print("EXPORTED", args.out)


main()
