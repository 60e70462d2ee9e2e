# The scenes of issue 42, built in Blender 3.4 and written as a user would write them, with the
# Cycles render of each as its reference:
#
#   blender -b --factory-startup -noaudio --python tests/data/interchange/make_interchange.py \
#       -- --out tests/data/interchange [--spp 2048] [--width 40] [--height 30]
#
# One base scene (Z-up): a 6 m floor with a 256 px checker image texture, a smooth red sphere, a
# blue cube; every material rough (Principled BSDF, roughness 1, specular 0.5 = glTF's 4%
# dielectric: GGX materials are issue 41's), a camera. Then, each exported with Blender's own exporters:
#   textured.glb   the base scene + a 600 W point light; its texture embedded (a bufferView)
#   lights.glb     the base scene + a 500 W point light + a 700 W spot light (60°, blend 0.2)
#   emissive.glb   the base scene lit only by an emissive quad (Principled emission 20,
#                  written through KHR_materials_emissive_strength)
#   emissive.obj   the same scene through the OBJ exporter (+ emissive.mtl, checker.png)
# and the Cycles references cycles_textured.exr, cycles_lights.exr, cycles_emissive.exr:
# Cycles CPU, --spp samples (2048: their noise is small beside drift's 256 spp), no denoising,
# no adaptive sampling, no clamping, box filter of 1 px, a black world, punctual lights of
# radius 0 (glTF lights are points), 8 bounces, linear float EXR. These settings are those of
# bench/cycles/gltf_cycles.py. tests/cli/test_interchange.sh renders the files with drift and
# compares; Blender runs only to regenerate (the outputs are in the repository).
import argparse
import math
import os
import sys

import bpy
from mathutils import Vector


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    p = argparse.ArgumentParser(prog="make_interchange.py")
    p.add_argument("--out", required=True)
    p.add_argument("--spp", type=int, default=2048)
    p.add_argument("--width", type=int, default=40)
    p.add_argument("--height", type=int, default=30)
    p.add_argument("--no-render", action="store_true", help="export only")
    return p.parse_args(argv)


def clear():
    for ob in list(bpy.data.objects):
        bpy.data.objects.remove(ob, do_unlink=True)
    for coll in (bpy.data.meshes, bpy.data.cameras, bpy.data.lights, bpy.data.materials,
                 bpy.data.images):
        for block in list(coll):
            coll.remove(block)


def material(name, base, emission=None, strength=1.0, image=None):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    nodes = m.node_tree.nodes
    bsdf = nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (*base, 1.0)
    bsdf.inputs["Metallic"].default_value = 0.0
    bsdf.inputs["Roughness"].default_value = 1.0
    bsdf.inputs["Specular"].default_value = 0.5  # F0 0.04: glTF's dielectric, no extension
    bsdf.inputs["IOR"].default_value = 1.5  # glTF's default: no KHR_materials_ior
    if emission is not None:
        bsdf.inputs["Emission"].default_value = (*emission, 1.0)
        bsdf.inputs["Emission Strength"].default_value = strength
    if image is not None:
        tex = nodes.new("ShaderNodeTexImage")
        tex.image = image
        m.node_tree.links.new(tex.outputs["Color"], bsdf.inputs["Base Color"])
    return m


def checker(out):
    """A 256 px checker of 32 px squares (sRGB 0.85 / 0.4 grey), saved as checker.png: few
    texels between squares, where Cycles (filtering the sRGB bytes) and drift (filtering
    linear values) differ."""
    size = 256
    img = bpy.data.images.new("checker", size, size, alpha=False)
    px = []
    for y in range(size):
        for x in range(size):
            v = 0.85 if ((x // 32) + (y // 32)) % 2 == 0 else 0.4
            px += [v, v, v, 1.0]
    img.pixels[:] = px
    img.filepath_raw = os.path.join(out, "checker.png")
    img.file_format = "PNG"
    img.save()
    img.filepath = img.filepath_raw
    return img


def place(ob, location, target=None):
    ob.location = location
    if target is not None:
        ob.rotation_euler = (Vector(target) - Vector(location)).to_track_quat("-Z", "Y").to_euler()


def base_scene(out):
    clear()
    scene = bpy.context.scene
    img = checker(out)
    bpy.ops.mesh.primitive_plane_add(size=6.0, location=(0, 0, 0))
    bpy.context.object.name = "Floor"
    bpy.context.object.data.materials.append(material("Floor", (1.0, 1.0, 1.0), image=img))
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.8, segments=32, ring_count=16,
                                         location=(-0.6, 0.3, 0.8))
    bpy.context.object.name = "Sphere"
    bpy.ops.object.shade_smooth()
    bpy.context.object.data.materials.append(material("Red", (0.7, 0.1, 0.1)))
    bpy.ops.mesh.primitive_cube_add(size=0.9, location=(1.2, -0.2, 0.45),
                                    rotation=(0, 0, math.radians(25)))
    bpy.context.object.name = "Cube"
    bpy.context.object.data.materials.append(material("Blue", (0.15, 0.25, 0.6)))
    cam = bpy.data.cameras.new("Camera")
    cam.sensor_fit = "VERTICAL"
    cam.angle_y = 0.7
    ob = bpy.data.objects.new("Camera", cam)
    scene.collection.objects.link(ob)
    place(ob, (0.0, -6.5, 3.2), target=(0.0, 0.0, 0.5))
    scene.camera = ob
    return scene


def point_light(scene, name, energy, location):
    light = bpy.data.lights.new(name, "POINT")
    light.energy = energy
    light.shadow_soft_size = 0.0
    ob = bpy.data.objects.new(name, light)
    scene.collection.objects.link(ob)
    place(ob, location)


def spot_light(scene, name, energy, location, target):
    light = bpy.data.lights.new(name, "SPOT")
    light.energy = energy
    light.color = (1.0, 0.95, 0.85)
    light.spot_size = math.radians(60)
    light.spot_blend = 0.2
    light.shadow_soft_size = 0.0
    ob = bpy.data.objects.new(name, light)
    scene.collection.objects.link(ob)
    place(ob, location, target=target)


def emissive_quad(scene):
    # A 1.6 m × 0.8 m quad 3.6 m up, facing down (its normal -Z): the only light. It sits just
    # above the camera's view: Cycles' emission is two-sided and drift's one-sided, so the
    # quad's back (lit in Cycles, black in drift) is kept out of the picture; its upward light
    # leaves the open scene in both.
    bpy.ops.mesh.primitive_plane_add(size=1.0, location=(0.3, 0.4, 3.6),
                                     rotation=(math.radians(180), 0, 0))
    ob = bpy.context.object
    ob.name = "Lamp"
    ob.scale = (1.6, 0.8, 1.0)
    bpy.ops.object.transform_apply(scale=True)
    ob.data.materials.append(material("Lamp", (0.0, 0.0, 0.0), emission=(1.0, 0.9, 0.75),
                                      strength=20.0))


def render(scene, args, path):
    world = bpy.data.worlds.new("black")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0
    scene.world = world
    r = scene.render
    r.engine = "CYCLES"
    r.resolution_x, r.resolution_y, r.resolution_percentage = args.width, args.height, 100
    r.film_transparent = False
    r.use_compositing = r.use_sequencer = False
    r.dither_intensity = 0.0
    r.use_file_extension = False
    r.image_settings.file_format = "OPEN_EXR"
    r.image_settings.color_depth = "16"
    r.image_settings.exr_codec = "ZIP"
    r.filepath = path
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0
    c = scene.cycles
    c.device = "CPU"
    c.samples = args.spp
    c.seed = 0
    c.use_adaptive_sampling = False
    c.use_denoising = False
    c.max_bounces = c.diffuse_bounces = c.glossy_bounces = 8
    c.transparent_max_bounces = 8
    c.sample_clamp_direct = c.sample_clamp_indirect = 0.0
    c.blur_glossy = 0.0
    c.caustics_reflective = c.caustics_refractive = True
    c.pixel_filter_type = "BOX"
    c.filter_width = 1.0
    bpy.ops.render.render(write_still=True)


def export_glb(path):
    bpy.ops.export_scene.gltf(filepath=path, export_format="GLB", export_cameras=True,
                              export_lights=True)


def main():
    args = parse_args()
    out = os.path.abspath(args.out)
    os.makedirs(out, exist_ok=True)
    jobs = []

    scene = base_scene(out)
    point_light(scene, "Point", 600.0, (1.5, -2.0, 3.5))
    export_glb(os.path.join(out, "textured.glb"))
    jobs.append("textured")
    if not args.no_render:
        render(scene, args, os.path.join(out, "cycles_textured.exr"))

    scene = base_scene(out)
    point_light(scene, "Point", 500.0, (2.0, -2.5, 3.0))
    spot_light(scene, "Spot", 700.0, (-1.5, -1.0, 4.0), target=(-0.5, 0.3, 0.0))
    export_glb(os.path.join(out, "lights.glb"))
    if not args.no_render:
        render(scene, args, os.path.join(out, "cycles_lights.exr"))

    scene = base_scene(out)
    emissive_quad(scene)
    export_glb(os.path.join(out, "emissive.glb"))
    bpy.ops.wm.obj_export(filepath=os.path.join(out, "emissive.obj"), export_materials=True,
                          export_normals=False, export_smooth_groups=True, path_mode="RELATIVE",
                          forward_axis="NEGATIVE_Z", up_axis="Y")
    if not args.no_render:
        render(scene, args, os.path.join(out, "cycles_emissive.exr"))
    print("WROTE", out)


main()
