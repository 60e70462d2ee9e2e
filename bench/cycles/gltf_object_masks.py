# One coverage mask per mesh object of a glTF file, rendered by Cycles from the file's camera,
# for `drift diff REF TEST --mask FILE` (per-object ꟻLIP, issue 41):
#
#   blender -b --factory-startup -noaudio --python bench/cycles/gltf_object_masks.py -- \
#       --gltf FILE.glb --width W --height H --out DIR [--spp N]
#
# writes DIR/mask_<object>.exr: the fraction of each pixel's camera rays whose first hit is that
# object (every object an opaque emitter, white for the one masked and black for the others, so
# what stands in front of it hides it; no lights, zero bounces, box filter of 1 px as
# gltf_cycles.py). Glass and every other material count as opaque here: a glass sphere's mask is
# the sphere's outline. `drift diff --mask` takes the pixels where the mask is >= 0.5.
import argparse
import os
import sys

import bpy


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    p = argparse.ArgumentParser(prog="gltf_object_masks.py")
    p.add_argument("--gltf", required=True)
    p.add_argument("--width", type=int, default=128)
    p.add_argument("--height", type=int, default=96)
    p.add_argument("--spp", type=int, default=256)
    p.add_argument("--out", required=True)
    return p.parse_args(argv)


def emitter(name, value):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    nodes = m.node_tree.nodes
    for n in list(nodes):
        nodes.remove(n)
    em = nodes.new("ShaderNodeEmission")
    em.inputs["Color"].default_value = (value, value, value, 1.0)
    em.inputs["Strength"].default_value = 1.0
    out = nodes.new("ShaderNodeOutputMaterial")
    m.node_tree.links.new(em.outputs[0], out.inputs["Surface"])
    return m


def main():
    args = parse_args()
    import numpy
    if not hasattr(numpy, "bool") or numpy.bool is not bool:
        numpy.bool = bool  # Debian 12's Blender 3.4 importer (see gltf_cycles.py)
    for ob in list(bpy.data.objects):
        bpy.data.objects.remove(ob, do_unlink=True)
    bpy.ops.import_scene.gltf(filepath=args.gltf)
    scene = bpy.context.scene
    cameras = [ob for ob in scene.objects if ob.type == "CAMERA"]
    if not cameras:
        raise SystemExit("gltf_object_masks.py: the file has no camera")
    scene.camera = cameras[0]
    for ob in [ob for ob in scene.objects if ob.type == "LIGHT"]:
        bpy.data.objects.remove(ob, do_unlink=True)
    world = bpy.data.worlds.new("black")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0
    scene.world = world
    white, black = emitter("mask_white", 1.0), emitter("mask_black", 0.0)
    meshes = [ob for ob in scene.objects if ob.type == "MESH"]

    r = scene.render
    r.engine = "CYCLES"
    r.resolution_x, r.resolution_y, r.resolution_percentage = args.width, args.height, 100
    r.film_transparent = False
    r.use_compositing = r.use_sequencer = False
    r.dither_intensity = 0.0
    r.use_file_extension = False
    r.image_settings.file_format = "OPEN_EXR"
    r.image_settings.color_depth = "32"
    r.image_settings.exr_codec = "NONE"
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    c = scene.cycles
    c.device = "CPU"
    c.samples = args.spp
    c.use_adaptive_sampling = False
    c.use_denoising = False
    c.max_bounces = 0
    c.pixel_filter_type = "BOX"
    c.filter_width = 1.0
    os.makedirs(args.out, exist_ok=True)
    for target in meshes:
        for ob in meshes:
            mat = white if ob == target else black
            ob.data.materials.clear()
            ob.data.materials.append(mat)
            for slot in ob.material_slots:
                slot.link = "OBJECT"
                slot.material = mat
        r.filepath = os.path.join(args.out, "mask_%s.exr" % target.name)
        bpy.ops.render.render(write_still=True)
        print("MASK", r.filepath)


main()
