# A glTF object animation written by Blender 3.4's own exporter, and Cycles' renders of three of
# its frames (issue 42: node animation played by `drift render --animation`):
#
#   blender -b --factory-startup -noaudio --python tests/data/gltf_anim/make_object_anim.py \
#       -- --out tests/data/gltf_anim [--spp 1024] [--width 40] [--height 30]
#
# The scene is make_interchange.py's base scene (textured.glb: a checker floor, a red sphere, a
# blue cube, its functions reused, the file run without its main()) with a still camera and
# keys at frames 0 and 24 (24 fps, Blender's Bezier easing) on three objects:
#   Cube   moves from (1.2, -0.2, 0.45) to (0.2, -1.4, 0.45) and turns from 25 to 115 degrees
#          about z;
#   Pivot  an empty at the origin that turns 0 to 50 degrees about z; the Sphere is its child
#          (an animated parent: the sphere swings round the origin);
#   Point  the 600 W point light moves from (1.5, -2.0, 3.5) to (-1.0, -2.5, 3.0).
# Exported as object_anim.glb (the exporter samples every frame, LINEAR, and writes frame 0's
# pose as the nodes' rest transforms); Cycles renders frames 0, 12 and 24 into
# cycles_object_0000.exr, _0012, _0024 with make_interchange.py's settings. tests/cli/test_gltf_animation.sh renders object_anim.glb with
# `drift render --animation 0:2 --fps 2` (t = 0, 0.5, 1 s: Blender's frames 0, 12, 24) and
# compares; Blender runs only to regenerate (the outputs are in the repository).
import math
import os
import sys

import bpy

here = os.path.dirname(os.path.abspath(__file__))
interchange = os.path.join(here, "..", "interchange", "make_interchange.py")
source = open(interchange).read().rsplit("\nmain()", 1)[0]
exec(compile(source, interchange, "exec"))  # base_scene, point_light, render, parse_args


def key(ob, frame, location=None, rotation_z=None):
    if location is not None:
        ob.location = location
        ob.keyframe_insert("location", frame=frame)
    if rotation_z is not None:
        ob.rotation_euler = (0.0, 0.0, math.radians(rotation_z))
        ob.keyframe_insert("rotation_euler", frame=frame)


def main():
    args = parse_args()
    if "--spp" not in sys.argv:
        args.spp = 1024
    out = os.path.abspath(args.out)
    os.makedirs(out, exist_ok=True)
    scene = base_scene(out)
    point_light(scene, "Point", 600.0, (1.5, -2.0, 3.5))
    scene.render.fps = 24
    scene.frame_start, scene.frame_end = 0, 24
    objects = bpy.data.objects
    cube, sphere, light = objects["Cube"], objects["Sphere"], objects["Point"]
    pivot = bpy.data.objects.new("Pivot", None)
    scene.collection.objects.link(pivot)
    sphere.parent = pivot  # the pivot stands at the origin unrotated: no parent inverse needed
    key(cube, 0, (1.2, -0.2, 0.45), 25.0)
    key(cube, 24, (0.2, -1.4, 0.45), 115.0)
    key(pivot, 0, rotation_z=0.0)
    key(pivot, 24, rotation_z=50.0)
    key(light, 0, (1.5, -2.0, 3.5))
    key(light, 24, (-1.0, -2.5, 3.0))
    bpy.ops.export_scene.gltf(filepath=os.path.join(out, "object_anim.glb"), export_format="GLB",
                              export_cameras=True, export_lights=True, export_animations=True)
    if not args.no_render:
        for frame in (0, 12, 24):
            scene.frame_set(frame)
            render(scene, args, os.path.join(out, "cycles_object_%04d.exr" % frame))
    os.remove(os.path.join(out, "checker.png"))  # embedded in the .glb (Cycles reads the file)
    print("WROTE", out)


main()
