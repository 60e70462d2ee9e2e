# A glTF camera animation written by Blender 3.4's own exporter, and Cycles' renders of three of
# its frames (issue 47):
#
#   blender -b --factory-startup -noaudio --python tests/data/gltf_anim/make_gltf_anim.py \
#       -- --out tests/data/gltf_anim [--spp 1024] [--width 40] [--height 30]
#
# The scene is make_interchange.py's base scene with its 600 W point light (textured.glb: a
# checker floor, a red sphere, a blue cube; its functions are reused, the file run without its
# main()). The camera is keyframed at frames 0 and 24 (24 fps, Blender's Bezier easing): it
# moves from (0, -6.5, 3.2) to (3.5, -5.0, 2.2), always aimed at (0, 0, 0.5), and rolls by 10
# degrees. Exported as anim.glb (the exporter samples the animation at every frame, LINEAR);
# Cycles renders frames 0, 12 and 24 into cycles_anim_0000.exr, _0012, _0024 with the
# settings of make_interchange.py (Cycles CPU, no denoising or adaptive sampling, box filter,
# black world, linear half-float EXR). tests/cli/test_gltf_animation.sh renders anim.glb with
# `drift render --animation 0:2 --fps 2` (t = 0, 0.5, 1 s: Blender's frames 0, 12, 24) and
# compares; Blender runs only to regenerate (the outputs are in the repository).
import math
import os
import sys

import bpy
from mathutils import Euler, Vector

here = os.path.dirname(os.path.abspath(__file__))
interchange = os.path.join(here, "..", "interchange", "make_interchange.py")
source = open(interchange).read().rsplit("\nmain()", 1)[0]
exec(compile(source, interchange, "exec"))  # base_scene, point_light, render, parse_args


def aim(ob, location, target, roll_degrees):
    ob.location = location
    q = (Vector(target) - Vector(location)).to_track_quat("-Z", "Y")
    ob.rotation_euler = (q @ Euler((0.0, 0.0, math.radians(roll_degrees))).to_quaternion()).to_euler()


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
    cam = scene.camera
    for frame, location, roll in ((0, (0.0, -6.5, 3.2), 0.0), (24, (3.5, -5.0, 2.2), 10.0)):
        aim(cam, location, (0.0, 0.0, 0.5), roll)
        cam.keyframe_insert("location", frame=frame)
        cam.keyframe_insert("rotation_euler", frame=frame)
    bpy.ops.export_scene.gltf(filepath=os.path.join(out, "anim.glb"), export_format="GLB",
                              export_cameras=True, export_lights=True, export_animations=True)
    if not args.no_render:
        for frame in (0, 12, 24):
            scene.frame_set(frame)
            render(scene, args, os.path.join(out, "cycles_anim_%04d.exr" % frame))
    os.remove(os.path.join(out, "checker.png"))  # embedded in the .glb (Cycles reads the file)
    print("WROTE", out)


main()
