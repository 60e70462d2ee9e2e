# Blender's own view transform of an EXR, for tests/cli/test_ocio_view.sh: the image is loaded
# as Blender loads a render (scene linear) and saved as an 8-bit PNG through the scene's
# display/view settings ("Save as Render"), with no dithering.
#
#   blender -b --factory-startup -noaudio --python tests/data/ocio/blender_view.py -- \
#       --in IN.exr --out OUT.png [--view Filmic] [--look None] [--exposure 0]
import argparse
import sys

import bpy


def main():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    p = argparse.ArgumentParser(prog="blender_view.py")
    p.add_argument("--in", dest="inp", required=True)
    p.add_argument("--out", required=True)
    p.add_argument("--view", default="Filmic")
    p.add_argument("--look", default="None")
    p.add_argument("--exposure", type=float, default=0.0)
    args = p.parse_args(argv)
    scene = bpy.context.scene
    scene.display_settings.display_device = "sRGB"
    scene.view_settings.view_transform = args.view
    scene.view_settings.look = args.look
    scene.view_settings.exposure = args.exposure
    scene.view_settings.gamma = 1.0
    scene.render.dither_intensity = 0.0
    settings = scene.render.image_settings
    settings.file_format = "PNG"
    settings.color_mode = "RGB"
    settings.color_depth = "8"
    image = bpy.data.images.load(args.inp)
    image.save_render(args.out, scene=scene)
    print("BLENDER_VIEW", args.view, args.out)


main()
