# Builds issue 22's scene in Blender and writes it with Blender's own glTF 2.0 exporter
# (io_scene_gltf2, bpy.ops.export_scene.gltf), as a user would: a 10 m plane, a red sphere of
# roughness 0.3, a grey cube, a 1000 W point light, an 800 W spot light, an emissive panel of
# strength 4, a camera. Run at test time (tests/cli/test_blender_gltf.sh):
#
#   blender -b --factory-startup -noaudio --python tests/data/gltf/export_blender_scene.py -- \
#       --out DIR [--roughness R]
#
# writes DIR/blender_export.glb (binary) and DIR/blender_export.gltf (+ .bin beside it). Every
# setting is the exporter's default except the ones a user exporting lights and cameras ticks
# (export_lights, export_cameras). Blender is Z-up; the exporter turns it to glTF's +Y up.
# --roughness R sets every material's roughness (the diffuse-only check of the Cycles harness).
import argparse
import math
import os
import sys

import bpy
from mathutils import Vector


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    p = argparse.ArgumentParser(prog="export_blender_scene.py")
    p.add_argument("--out", required=True, help="folder for blender_export.glb and .gltf")
    p.add_argument("--roughness", type=float, default=None)
    return p.parse_args(argv)


def material(name, base, roughness, emission=None, strength=1.0):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    bsdf = m.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (*base, 1.0)
    bsdf.inputs["Metallic"].default_value = 0.0
    bsdf.inputs["Roughness"].default_value = roughness
    if emission is not None:
        bsdf.inputs["Emission"].default_value = (*emission, 1.0)
        bsdf.inputs["Emission Strength"].default_value = strength
    return m


def place(ob, location, target=None):
    ob.location = location
    if target is not None:
        # Point the object's -Z (lights, cameras) at target with +Y up, as a Track To would.
        ob.rotation_euler = (Vector(target) - Vector(location)).to_track_quat("-Z", "Y").to_euler()


def main():
    args = parse_args()
    r = args.roughness
    for ob in list(bpy.data.objects):
        bpy.data.objects.remove(ob, do_unlink=True)
    for coll in (bpy.data.meshes, bpy.data.cameras, bpy.data.lights, bpy.data.materials):
        for block in list(coll):
            coll.remove(block)
    scene = bpy.context.scene
    scene.render.resolution_x, scene.render.resolution_y = 640, 480

    bpy.ops.mesh.primitive_plane_add(size=10.0, location=(0, 0, 0))
    bpy.context.object.name = "Plane"
    bpy.context.object.data.materials.append(material("Floor", (0.8, 0.8, 0.8), r if r is not None else 1.0))

    bpy.ops.mesh.primitive_uv_sphere_add(radius=1.0, segments=32, ring_count=16, location=(0, 0, 1))
    bpy.context.object.name = "Sphere"
    bpy.ops.object.shade_smooth()
    bpy.context.object.data.materials.append(material("Red", (0.8, 0.05, 0.05), r if r is not None else 0.3))

    bpy.ops.mesh.primitive_cube_add(size=1.0, location=(2.5, 1.0, 0.5),
                                    rotation=(0, 0, math.radians(20)))
    bpy.context.object.name = "Cube"
    bpy.context.object.data.materials.append(material("Grey", (0.5, 0.5, 0.5), r if r is not None else 0.6))

    # A 0.8 m panel standing upright (its +Z normal turned to -Y, towards the camera).
    bpy.ops.mesh.primitive_plane_add(size=0.8, location=(-2.5, 2.0, 1.2),
                                     rotation=(math.radians(90), 0, 0))
    bpy.context.object.name = "Panel"
    bpy.context.object.data.materials.append(
        material("Panel", (0.0, 0.0, 0.0), 1.0, emission=(1.0, 0.9, 0.7), strength=4.0))

    point = bpy.data.lights.new("Point", "POINT")
    point.energy = 1000.0
    ob = bpy.data.objects.new("Point", point)
    scene.collection.objects.link(ob)
    place(ob, (1.5, -3.0, 4.0))

    spot = bpy.data.lights.new("Spot", "SPOT")
    spot.energy = 800.0
    spot.color = (1.0, 0.95, 0.9)
    spot.spot_size = math.radians(60)
    spot.spot_blend = 0.15
    ob = bpy.data.objects.new("Spot", spot)
    scene.collection.objects.link(ob)
    place(ob, (-3.0, 0.0, 5.0), target=(0, 0, 0))

    cam = bpy.data.cameras.new("Camera")
    cam.sensor_fit = "VERTICAL"
    cam.angle_y = 0.6
    ob = bpy.data.objects.new("Camera", cam)
    scene.collection.objects.link(ob)
    place(ob, (0.0, -9.0, 3.0), target=(0.0, 0.0, 0.8))
    scene.camera = ob

    os.makedirs(args.out, exist_ok=True)
    for fmt, ext in (("GLB", "glb"), ("GLTF_SEPARATE", "gltf")):
        bpy.ops.export_scene.gltf(filepath=os.path.join(args.out, "blender_export." + ext),
                                  export_format=fmt, export_cameras=True, export_lights=True)
    print("EXPORTED", args.out)


main()
