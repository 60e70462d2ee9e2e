# Blender Cycles (CPU) render of a glTF 2.0 file through Blender's own glTF importer, for
# comparison with `drift render` of the same file (tests/cli/test_blender_gltf.sh).
#
#   blender -b --factory-startup -noaudio --python bench/cycles/gltf_cycles.py -- \
#       --gltf FILE.gltf --spp N --width W --height H --out FILE.exr [--threads T]
#
# Settings as in cornell_cycles.py where they matter for agreement with drift's reference: no
# denoising, no adaptive sampling, no clamping, box filter of 1 px, view transform Standard,
# exposure 0, a black world, linear float EXR (compression NONE, so exr_mean.py reads it).
# Punctual lights get radius 0 (glTF lights are points; Blender's importer gives them a soft
# size). Prints CYCLES_MEAN r g b. Needs python3-numpy (scripts/install-cycles.sh installs it).
import argparse
import array
import sys

import bpy


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    p = argparse.ArgumentParser(prog="gltf_cycles.py")
    p.add_argument("--gltf", required=True)
    p.add_argument("--spp", type=int, default=256)
    p.add_argument("--width", type=int, default=128)
    p.add_argument("--height", type=int, default=96)
    p.add_argument("--threads", type=int, default=2)
    p.add_argument("--max-bounces", type=int, default=8)
    p.add_argument("--out", required=True)
    p.add_argument("--seed", type=int, default=0, help="Cycles' sampling seed")
    p.add_argument("--multiscatter", action="store_true",
                   help="set each Principled BSDF to Multiscatter GGX (energy-conserving rough "
                        "metals, as drift's GGX material compensates; issue 41)")
    p.add_argument("--rr-min-bounces", type=int, default=None, metavar="N",
                   help="Cycles min_light_bounces N (Cycles adds one: N=1 starts the roulette at "
                        "the 4th vertex, as drift's rr_depth 3) and light threshold 0, as "
                        "cornell_cycles.py; default: Blender's defaults (roulette from the 3rd "
                        "vertex, light threshold 0.01)")
    p.add_argument("--lambert", action="store_true",
                   help="replace each Principled BSDF by a Diffuse BSDF of its base colour "
                        "(emission kept): separates the material model from the light units")
    return p.parse_args(argv)


def main():
    args = parse_args()
    # Debian 12's Blender 3.4 glTF importer still uses np.bool, which Debian's NumPy 1.24 has
    # removed; restore the alias (it was the builtin bool) so the importer runs.
    import numpy
    if not hasattr(numpy, "bool") or numpy.bool is not bool:
        numpy.bool = bool
    for ob in list(bpy.data.objects):
        bpy.data.objects.remove(ob, do_unlink=True)
    bpy.ops.import_scene.gltf(filepath=args.gltf)
    scene = bpy.context.scene
    if args.multiscatter:
        for mat in bpy.data.materials:
            for node in (mat.node_tree.nodes if mat.use_nodes else []):
                if node.type == "BSDF_PRINCIPLED":
                    node.distribution = "MULTI_GGX"
    if args.lambert:
        for mat in bpy.data.materials:
            nodes = mat.node_tree.nodes if mat.use_nodes else []
            for node in [n for n in nodes if n.type == "BSDF_PRINCIPLED"]:
                diffuse = nodes.new("ShaderNodeBsdfDiffuse")
                diffuse.inputs["Color"].default_value = node.inputs["Base Color"].default_value
                emission = nodes.new("ShaderNodeEmission")
                emission.inputs["Color"].default_value = node.inputs["Emission"].default_value
                emission.inputs["Strength"].default_value = node.inputs["Emission Strength"].default_value
                add = nodes.new("ShaderNodeAddShader")
                mat.node_tree.links.new(diffuse.outputs[0], add.inputs[0])
                mat.node_tree.links.new(emission.outputs[0], add.inputs[1])
                for link in list(node.outputs[0].links):
                    mat.node_tree.links.new(add.outputs[0], link.to_socket)
    cameras = [ob for ob in scene.objects if ob.type == "CAMERA"]
    if not cameras:
        raise SystemExit("gltf_cycles.py: the file has no camera")
    scene.camera = cameras[0]
    for ob in scene.objects:
        if ob.type == "LIGHT" and ob.data.type in ("POINT", "SPOT"):
            ob.data.shadow_soft_size = 0.0
    world = bpy.data.worlds.new("black")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0
    scene.world = world

    r = scene.render
    r.engine = "CYCLES"
    r.resolution_x, r.resolution_y, r.resolution_percentage = args.width, args.height, 100
    r.threads_mode, r.threads = "FIXED", args.threads
    r.film_transparent = False
    r.use_compositing = r.use_sequencer = False
    r.dither_intensity = 0.0
    r.use_file_extension = False
    r.image_settings.file_format = "OPEN_EXR"
    r.image_settings.color_depth = "32"
    r.image_settings.exr_codec = "NONE"
    r.filepath = args.out
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0
    c = scene.cycles
    c.device = "CPU"
    c.samples = args.spp
    c.seed = args.seed
    c.use_adaptive_sampling = False
    c.use_denoising = False
    c.max_bounces = c.diffuse_bounces = c.glossy_bounces = args.max_bounces
    c.sample_clamp_direct = c.sample_clamp_indirect = 0.0
    c.blur_glossy = 0.0
    c.pixel_filter_type = "BOX"
    c.filter_width = 1.0
    if args.rr_min_bounces is not None:
        c.min_light_bounces = c.min_transparent_bounces = max(0, args.rr_min_bounces)
        c.light_sampling_threshold = 0.0
    bpy.ops.render.render(write_still=True)
    img = bpy.data.images.load(args.out)
    px = array.array("f", img.pixels[:])
    n = len(px) // 4
    print("CYCLES_MEAN %.9g %.9g %.9g" % tuple(sum(px[k::4]) / n for k in range(3)))


main()
