# Blender Cycles (CPU) render of a drift scene JSON whose meshes are OBJ files (the Breakfast
# Room), with the materials mapped the way drift reads their MTL, for `drift bench cycles`.
#
#   blender -b --factory-startup -noaudio --python bench/cycles/obj_cycles.py -- \
#       --scene FILE.json --spp N --max-depth D --threads T --width W --height H --out FILE.exr
#
# - Geometry: Blender's C++ OBJ importer (wm.obj_import, fast enough that the whole process is
#   not dominated by a Python parser) with forward Y and up Z: the identity, so Blender's
#   coordinates are drift's and the camera is placed from the JSON as it is. Normals (vn) come
#   in as custom split normals, as drift (assimp) interpolates them.
# - Materials: every material's nodes are replaced from the MTL, as drift reads a non-Blender
#   MTL (src/io/scene_obj.c): Kd -> Diffuse BSDF (roughness 0, Lambert), Ke -> Emission of
#   radiance Ke (strength 1), both added where both are given. drift's emitters are one-sided;
#   the scene's one emitter is a closed sphere seen from outside, where that makes no
#   difference. A material the MTL does not define is grey 0.6 (assimp's default diffuse).
# - Camera: position/target/up/fov_y of the JSON, vertical sensor fit; the bench's square size.
# - World: the JSON's constant environment colour, strength 1 (black without one).
# - Sampling as cornell_cycles.py (configure()): box filter 1 px, no adaptive sampling,
#   clamping, denoising or light threshold; max_bounces D + offset (-1: drift's --max-depth D);
#   Russian roulette with min_light_bounces N (N = 1: from the 4th vertex, as drift's rr_depth 3).
# Prints CYCLES_TIME render_seconds=... render_cpu_seconds=... (Sample 0/N -> N/N, as
# cornell_cycles.py; the CPU time of all threads over the same window) and CYCLES_MEAN r g b.
import argparse
import json
import math
import os
import sys
import time

import bpy
from mathutils import Matrix, Vector

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import cornell_cycles as cc  # noqa: E402  (Timer, render_captured, configure, image_mean)


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    p = argparse.ArgumentParser(prog="obj_cycles.py")
    p.add_argument("--scene", required=True, help="drift scene JSON with OBJ meshes")
    p.add_argument("--spp", type=int, required=True)
    p.add_argument("--max-depth", type=int, required=True)
    p.add_argument("--bounces-offset", type=int, default=-1)
    p.add_argument("--threads", type=int, default=1)
    p.add_argument("--width", type=int, default=256)
    p.add_argument("--height", type=int, default=256)
    p.add_argument("--out", required=True)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--rr-min-bounces", type=int, default=1)
    args = p.parse_args(argv)
    # configure() reads these cornell_cycles.py options too.
    args.russian_roulette, args.exr_codec, args.rgba = True, "NONE", False
    return args


def load_mtl(path):
    mats, cur = {}, None
    with open(path) as f:
        for line in f:
            t = line.split()
            if not t or t[0].startswith("#"):
                continue
            if t[0] == "newmtl":
                cur = mats.setdefault(" ".join(t[1:]), {})
            elif t[0] in ("Kd", "Ke") and cur is not None:
                cur[t[0]] = tuple(float(x) for x in t[1:4])
    return mats


def mtl_of(obj_path):
    mats = {}
    with open(obj_path) as f:
        for line in f:
            if line.startswith("mtllib"):
                mats.update(load_mtl(os.path.join(os.path.dirname(obj_path), line[6:].strip())))
            elif line.startswith(("v ", "f ")):
                break  # the libraries come first in the files drift's scenes use
    return mats


def remap_material(m, spec):
    m.use_nodes = True
    nt = m.node_tree
    for n in list(nt.nodes):
        nt.nodes.remove(n)
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    out.target = "CYCLES"
    kd = spec.get("Kd", (0.6, 0.6, 0.6) if not spec else (0.0, 0.0, 0.0))
    ke = spec.get("Ke", (0.0, 0.0, 0.0))
    shader = None
    if max(kd) > 0.0:
        d = nt.nodes.new("ShaderNodeBsdfDiffuse")
        d.inputs["Color"].default_value = (kd[0], kd[1], kd[2], 1.0)
        d.inputs["Roughness"].default_value = 0.0
        shader = d.outputs["BSDF"]
    if max(ke) > 0.0:
        e = nt.nodes.new("ShaderNodeEmission")
        e.inputs["Color"].default_value = (ke[0], ke[1], ke[2], 1.0)
        e.inputs["Strength"].default_value = 1.0
        if shader is None:
            shader = e.outputs["Emission"]
        else:
            add = nt.nodes.new("ShaderNodeAddShader")
            nt.links.new(shader, add.inputs[0])
            nt.links.new(e.outputs["Emission"], add.inputs[1])
            shader = add.outputs["Shader"]
        m.cycles.sample_as_light = True
    if shader is None:
        d = nt.nodes.new("ShaderNodeBsdfDiffuse")
        d.inputs["Color"].default_value = (0.0, 0.0, 0.0, 1.0)
        shader = d.outputs["BSDF"]
    nt.links.new(shader, out.inputs["Surface"])


def build_scene(args):
    for ob in list(bpy.data.objects):
        bpy.data.objects.remove(ob, do_unlink=True)
    with open(args.scene) as f:
        desc = json.load(f)
    base = os.path.dirname(os.path.abspath(args.scene))
    scene = bpy.context.scene
    specs = {}
    for mesh in desc.get("meshes", []):
        path = os.path.normpath(os.path.join(base, mesh["path"]))
        if not path.lower().endswith(".obj"):
            raise SystemExit("obj_cycles.py: %s is not an OBJ" % path)
        specs.update(mtl_of(path))
        bpy.ops.wm.obj_import(filepath=path, forward_axis="Y", up_axis="Z")
    for m in bpy.data.materials:
        # The importer names a material as the MTL does (a duplicate gets ".001").
        name = m.name if m.name in specs else m.name.rsplit(".", 1)[0]
        remap_material(m, specs.get(name, {}))
    for ob in scene.objects:  # an object without a material slot: assimp's default grey
        if ob.type == "MESH" and not ob.data.materials:
            m = bpy.data.materials.new("drift-default")
            remap_material(m, {})
            ob.data.materials.append(m)

    cam_desc = desc["camera"]
    eye = Vector(cam_desc["position"])
    fwd = (Vector(cam_desc["target"]) - eye).normalized()
    right = fwd.cross(Vector(cam_desc.get("up", (0.0, 1.0, 0.0)))).normalized()
    up = right.cross(fwd)
    cam_data = bpy.data.cameras.new("camera")
    cam_data.type = "PERSP"
    cam_data.sensor_fit = "VERTICAL"
    cam_data.angle_y = math.radians(cam_desc.get("fov_y", 45.0))
    cam_data.clip_start = 1e-3
    cam_data.clip_end = 1e5
    cam = bpy.data.objects.new("camera", cam_data)
    cam.matrix_world = Matrix((
        (right.x, up.x, -fwd.x, eye.x),
        (right.y, up.y, -fwd.y, eye.y),
        (right.z, up.z, -fwd.z, eye.z),
        (0.0, 0.0, 0.0, 1.0)))
    scene.collection.objects.link(cam)
    scene.camera = cam

    world = bpy.data.worlds.new("environment")
    world.use_nodes = True
    bg = world.node_tree.nodes.get("Background")
    color = desc.get("environment", {}).get("color", (0.0, 0.0, 0.0))
    bg.inputs["Color"].default_value = (color[0], color[1], color[2], 1.0)
    bg.inputs["Strength"].default_value = 1.0 if max(color) > 0.0 else 0.0
    scene.world = world


def main():
    args = parse_args()
    build_scene(args)
    depth = cc.configure(args)
    args.rr_min_bounces = max(0, args.rr_min_bounces)
    bpy.context.scene.cycles.min_light_bounces = args.rr_min_bounces
    bpy.context.scene.cycles.min_transparent_bounces = args.rr_min_bounces
    timer = cc.Timer(args.spp)
    bpy.app.handlers.render_pre.append(timer.pre)
    bpy.app.handlers.render_post.append(timer.post)
    bpy.app.handlers.render_stats.append(timer.stats)
    print("CYCLES_CONFIG blender=%s spp=%d max_bounces=%d min_light_bounces=%d threads=%d" %
          (bpy.app.version_string, args.spp, depth, args.rr_min_bounces, args.threads), flush=True)
    t0 = time.perf_counter()
    cc.render_captured(timer)
    render_s, cpu_s = time.perf_counter() - t0, float("nan")
    if timer.t_first_sample is not None and timer.t_last_sample is not None:
        render_s = timer.t_last_sample - timer.t_first_sample
        cpu_s = timer.cpu_last_sample - timer.cpu_first_sample  # all threads, same window
    print("CYCLES_TIME render_seconds=%.6f render_cpu_seconds=%.6f spp=%d width=%d height=%d "
          "threads=%d depth=%d" % (render_s, cpu_s, args.spp, args.width, args.height,
                                   args.threads, args.max_depth), flush=True)
    print("CYCLES_MEAN %.6f %.6f %.6f" % cc.image_mean(args.out)[1], flush=True)


if __name__ == "__main__":
    try:
        main()
    except SystemExit:
        raise
    except BaseException:
        import traceback
        traceback.print_exc()
        sys.stdout.flush()
        os._exit(1)
