# Blender Cycles (CPU) reference render of the official Cornell box, for comparison with drift.
#
#   blender -b --factory-startup -noaudio --python bench/cycles/cornell_cycles.py -- \
#       --spp N --max-depth D --threads T --width W --height H --out FILE.exr [--seed S]
#
# Builds the scene directly from cornell_box_official.obj/.mtl (no OBJ importer involved), renders
# with Cycles on the CPU and writes a linear, full-float (32-bit) OpenEXR. Prints two
# machine-readable lines on stdout:
#
#   CYCLES_TIME render_seconds=<s> sync_seconds=<s> spp=<n> width=<w> height=<h> threads=<t> depth=<d>
#   CYCLES_MEAN <r> <g> <b>
#
# Timing (see also bench/cycles/README.md):
#   Timestamps (time.perf_counter) are taken in bpy.app.handlers: render_pre, render_stats (called
#   synchronously after every background status line "Fra:1 Mem:... | Sample k/N" is printed; in
#   3.4 the handler gets no text, so stdout goes to a temp file during the render and the handler
#   reads the line just written) and render_post.
#   * render_seconds = first status "Sample 0/N" (path tracing starts; scene sync, BVH build and
#     kernel setup are done) -> last status "Sample N/N" (all samples traced). Pure path tracing
#     plus Cycles' small per-update film read-backs; NO scene export, NO BVH build, NO EXR write.
#   * sync_seconds   = render_pre -> "Sample 0/N": Blender depsgraph -> Cycles scene sync,
#     shader compile, BVH build (Embree), film/buffer setup.
#   * CYCLES_TIME_DETAIL also prints total_seconds (render_pre -> render_post),
#     render_cpu_seconds (process CPU time, time.process_time, over the same window as
#     render_seconds: all threads summed; with --threads 1 it is the path-tracing CPU time and is
#     robust when other processes compete for the cores) and Cycles' own render_time /
#     synchronization_time read back from the EXR metadata (10 ms resolution; should agree).
#   Resolution: perf_counter (sub-microsecond); the status callbacks fire synchronously from the
#   render thread, so the error is the latency of one status update (~ms).
#
# Conventions (must match drift's reference path tracer):
#   * Geometry in millimetres as in the OBJ; drift (x, y, z) [right-handed, y-up] maps to Blender
#     (X, Y, Z) = (x, -z, y) [right-handed, z-up]. That is a proper rotation (det +1, same as the
#     Blender OBJ importer's default forward=-Z, up=Y), so the image is identical: red wall (x~556)
#     on the image LEFT.
#   * Camera: eye (278, 273, -800), look +z, up +y (drift) -> Blender eye (278, 800, 273), look -Y,
#     up +Z; lens 35 mm on a 25 mm sensor, sensor fit VERTICAL -> vertical FOV 39.3077 deg (and the
#     same horizontally for square images).
#   * Walls/blocks: Diffuse BSDF (roughness 0 = Lambert), colour = .mtl Kd (scene-linear RGB).
#   * Light: Emission shader, colour = .mtl Ke, strength 1. In Cycles the radiance of an emission
#     closure is colour * strength (emissive_simple_eval returns 1, no 1/pi), so L = Ke exactly;
#     a camera ray hitting the light gives pixel value Ke. Cycles' emission is two-sided
#     (--one-sided-light makes the back black; irrelevant here: the back faces the ceiling 0.1 mm
#     away).
#   * World black (strength 0). Flat shading (face normals), triangles (v0 v1 v2)(v0 v2 v3).
#   * max bounces = D (+ --bounces-offset): Cycles counts bounces AFTER the first hit:
#     max_bounces 0 = direct lighting only (the BSDF ray from the last vertex is still traced and
#     its emission, MIS-weighted, added). So Cycles D <=> up to D+1 scattering vertices <=> drift /
#     pbrt --max-depth D+1. diffuse/glossy/transmission bounces = same, volume 0.
#   * Russian roulette off by default (min_light_bounces = max_bounces) = a plain path tracer of
#     fixed depth; --russian-roulette restores Cycles' default (min_light_bounces 0),
#     --rr-min-bounces N sets min_light_bounces N. Cycles adds one to it (integrator.cpp,
#     "kintegrator->min_bounce = min_bounce + 1") and tests "bounce <= min_bounce" at the vertex
#     of bounce index k (0 = the camera ray's hit), so the roulette first acts at vertex N + 2
#     (0-based), after N + 2 bounces of throughput: N=1 ~ drift's rr_depth 3 (N=2 started it a
#     vertex later than drift, and Cycles' relMSE at equal spp was 0.84x drift's for it; both survive
#     with sqrt(max throughput), pbrt-v4 with max throughput).
#   * No clamping (direct/indirect 0), filter glossy 0, light threshold 0, no adaptive sampling,
#     no denoising, box pixel filter of width 1 px, exposure 0, gamma 1, view transform Standard.
#     Cycles still does next-event estimation + MIS (material "multiple importance" on).
import argparse
import array
import math
import os
import sys
import time

import bpy

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.abspath(os.path.join(HERE, "..", ".."))
DEFAULT_OBJ = os.path.join(REPO, "shared", "scenes", "cornell-box", "cornell_box_official.obj")
if not os.path.exists(DEFAULT_OBJ):
    DEFAULT_OBJ = "/work/shared/scenes/cornell-box/cornell_box_official.obj"


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    p = argparse.ArgumentParser(prog="cornell_cycles.py")
    p.add_argument("--spp", type=int, required=True)
    p.add_argument("--max-depth", type=int, required=True,
                   help="Cycles max bounces (0 = direct lighting only)")
    p.add_argument("--bounces-offset", type=int, default=0,
                   help="Cycles max_bounces = max-depth + offset (to align depth conventions)")
    p.add_argument("--threads", type=int, default=1)
    p.add_argument("--width", type=int, default=512)
    p.add_argument("--height", type=int, default=512)
    p.add_argument("--out", required=True, help="output .exr (linear, 32-bit float)")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--obj", default=DEFAULT_OBJ)
    p.add_argument("--png", default=None, help="also write an sRGB PNG preview (Standard view)")
    p.add_argument("--exr-codec", default="NONE",
                   help="OpenEXR compression: NONE (default, simplest to read), ZIP, PIZ, ...")
    p.add_argument("--rgba", action="store_true", help="write RGBA instead of RGB channels")
    p.add_argument("--russian-roulette", action="store_true",
                   help="Cycles' default Russian roulette from the first bounce (off by default)")
    p.add_argument("--rr-min-bounces", type=int, default=None, metavar="N",
                   help="Russian roulette after N bounces (Cycles min_light_bounces; implies RR). "
                        "N=1 starts RR at the 4th path vertex, like drift's rr_depth 3")
    p.add_argument("--one-sided-light", action="store_true",
                   help="make the back face of the light black (Cycles emission is two-sided)")
    p.add_argument("--light-diffuse", action="store_true",
                   help="add the light's .mtl Kd as a diffuse BSDF on the light (default: emitter only)")
    return p.parse_args(argv)


def load_obj(path):
    """Minimal OBJ/MTL reader for cornell_box_official.obj: returns (materials, objects)."""
    mats = {}
    objects = []  # list of (name, material, [faces as lists of (x,y,z)])
    verts = []
    cur_obj, cur_mtl = None, None
    base = os.path.dirname(path)
    with open(path) as f:
        for line in f:
            t = line.split()
            if not t or t[0].startswith("#"):
                continue
            if t[0] == "mtllib":
                mats.update(load_mtl(os.path.join(base, " ".join(t[1:]))))
            elif t[0] == "o":
                cur_obj = [t[1], cur_mtl, []]
                objects.append(cur_obj)
            elif t[0] == "usemtl":
                cur_mtl = t[1]
                if cur_obj is not None:
                    if cur_obj[2]:  # material change inside an object: start a new piece
                        cur_obj = [cur_obj[0] + "." + cur_mtl, cur_mtl, []]
                        objects.append(cur_obj)
                    else:
                        cur_obj[1] = cur_mtl
            elif t[0] == "v":
                verts.append(tuple(float(x) for x in t[1:4]))
            elif t[0] == "f":
                idx = []
                for tok in t[1:]:
                    i = int(tok.split("/")[0])
                    idx.append(i - 1 if i > 0 else len(verts) + i)
                if cur_obj is None:
                    cur_obj = ["default", cur_mtl, []]
                    objects.append(cur_obj)
                cur_obj[2].append([verts[i] for i in idx])
    return mats, objects


def load_mtl(path):
    mats, cur = {}, None
    with open(path) as f:
        for line in f:
            t = line.split()
            if not t or t[0].startswith("#"):
                continue
            if t[0] == "newmtl":
                cur = t[1]
                mats[cur] = {"Kd": (0.0, 0.0, 0.0), "Ke": (0.0, 0.0, 0.0)}
            elif t[0] in ("Kd", "Ke") and cur is not None:
                mats[cur][t[0]] = tuple(float(x) for x in t[1:4])
    return mats


def to_blender(p):
    # drift/OBJ (x, y, z), right-handed y-up  ->  Blender (x, -z, y), right-handed z-up.
    x, y, z = p
    return (x, -z, y)


def make_material(name, kd, ke, args):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    nt = m.node_tree
    for n in list(nt.nodes):
        nt.nodes.remove(n)
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    out.target = "CYCLES"
    if max(ke) > 0.0:
        em = nt.nodes.new("ShaderNodeEmission")
        em.inputs["Color"].default_value = (ke[0], ke[1], ke[2], 1.0)
        em.inputs["Strength"].default_value = 1.0  # radiance = Color * Strength (W/m^2/sr units)
        shader = em.outputs["Emission"]
        if args.light_diffuse:
            d = nt.nodes.new("ShaderNodeBsdfDiffuse")
            d.inputs["Color"].default_value = (kd[0], kd[1], kd[2], 1.0)
            d.inputs["Roughness"].default_value = 0.0
            add = nt.nodes.new("ShaderNodeAddShader")
            nt.links.new(shader, add.inputs[0])
            nt.links.new(d.outputs["BSDF"], add.inputs[1])
            shader = add.outputs["Shader"]
        if args.one_sided_light:
            geo = nt.nodes.new("ShaderNodeNewGeometry")
            mix = nt.nodes.new("ShaderNodeMixShader")  # fac 1 (back face) -> empty = black
            nt.links.new(geo.outputs["Backfacing"], mix.inputs["Fac"])
            nt.links.new(shader, mix.inputs[1])
            shader = mix.outputs["Shader"]
        nt.links.new(shader, out.inputs["Surface"])
        m.cycles.sample_as_light = True  # next-event estimation + MIS on the emitter
    else:
        d = nt.nodes.new("ShaderNodeBsdfDiffuse")
        d.inputs["Color"].default_value = (kd[0], kd[1], kd[2], 1.0)
        d.inputs["Roughness"].default_value = 0.0  # Lambert
        nt.links.new(d.outputs["BSDF"], out.inputs["Surface"])
    return m


def build_scene(args):
    # Empty the factory-startup scene (cube, lamp, camera).
    for ob in list(bpy.data.objects):
        bpy.data.objects.remove(ob, do_unlink=True)
    for coll in (bpy.data.meshes, bpy.data.lights, bpy.data.cameras, bpy.data.materials):
        for item in list(coll):
            coll.remove(item)

    scene = bpy.context.scene
    mats, objects = load_obj(args.obj)
    bl_mats = {n: make_material(n, v["Kd"], v["Ke"], args) for n, v in mats.items()}

    ntris = 0
    for name, mtl, faces in objects:
        verts, tris, vmap = [], [], {}
        for face in faces:
            ids = []
            for p in face:
                q = to_blender(p)
                if q not in vmap:
                    vmap[q] = len(verts)
                    verts.append(q)
                ids.append(vmap[q])
            for k in range(1, len(ids) - 1):  # fan: (v0 v1 v2) (v0 v2 v3), keeps winding
                tris.append((ids[0], ids[k], ids[k + 1]))
        me = bpy.data.meshes.new(name)
        me.from_pydata(verts, [], tris)
        me.update()
        for poly in me.polygons:
            poly.use_smooth = False
        me.materials.append(bl_mats[mtl])
        ob = bpy.data.objects.new(name, me)
        scene.collection.objects.link(ob)
        ntris += len(tris)

    # Camera: look-at in drift coordinates, converted.
    eye = to_blender((278.0, 273.0, -800.0))
    fwd = to_blender((0.0, 0.0, 1.0))
    up = to_blender((0.0, 1.0, 0.0))
    right = (fwd[1] * up[2] - fwd[2] * up[1], fwd[2] * up[0] - fwd[0] * up[2],
             fwd[0] * up[1] - fwd[1] * up[0])  # fwd x up = image right
    from mathutils import Matrix
    cam_data = bpy.data.cameras.new("camera")
    cam_data.type = "PERSP"
    cam_data.lens_unit = "MILLIMETERS"
    cam_data.lens = 35.0
    cam_data.sensor_fit = "VERTICAL"
    cam_data.sensor_height = 25.0
    cam_data.sensor_width = 25.0
    cam_data.shift_x = cam_data.shift_y = 0.0
    cam_data.clip_start = 1.0      # mm
    cam_data.clip_end = 100000.0   # mm
    cam_data.dof.use_dof = False
    cam = bpy.data.objects.new("camera", cam_data)
    # Blender camera: local +X = image right, +Y = image up, -Z = view direction.
    cam.matrix_world = Matrix((
        (right[0], up[0], -fwd[0], eye[0]),
        (right[1], up[1], -fwd[1], eye[1]),
        (right[2], up[2], -fwd[2], eye[2]),
        (0.0, 0.0, 0.0, 1.0)))
    scene.collection.objects.link(cam)
    scene.camera = cam

    # Black world.
    world = bpy.data.worlds.new("black")
    world.use_nodes = True
    bg = world.node_tree.nodes.get("Background")
    bg.inputs["Color"].default_value = (0.0, 0.0, 0.0, 1.0)
    bg.inputs["Strength"].default_value = 0.0
    world.color = (0.0, 0.0, 0.0)
    scene.world = world
    return ntris


def rr_min_bounces(args, depth):
    if args.rr_min_bounces is not None:
        return max(0, args.rr_min_bounces)
    return 0 if args.russian_roulette else max(depth, 0)


def configure(args):
    scene = bpy.context.scene
    r = scene.render
    r.engine = "CYCLES"
    r.resolution_x, r.resolution_y = args.width, args.height
    r.resolution_percentage = 100
    r.pixel_aspect_x = r.pixel_aspect_y = 1.0
    r.use_border = False
    r.threads_mode = "FIXED"
    r.threads = args.threads
    r.use_persistent_data = False
    r.film_transparent = False
    r.use_motion_blur = False
    r.use_compositing = False
    r.use_sequencer = False
    r.dither_intensity = 0.0
    r.use_file_extension = False
    r.use_stamp = False

    c = scene.cycles
    c.device = "CPU"
    c.feature_set = "SUPPORTED"
    c.shading_system = False  # SVM, not OSL
    c.samples = args.spp
    c.use_adaptive_sampling = False
    c.time_limit = 0.0
    c.use_denoising = False
    c.use_preview_denoising = False
    depth = args.max_depth + args.bounces_offset
    c.max_bounces = depth
    c.diffuse_bounces = depth
    c.glossy_bounces = depth
    c.transmission_bounces = depth
    c.transparent_max_bounces = depth
    c.volume_bounces = 0
    # Cycles: no roulette while bounce <= min_light_bounces; then survive with
    # min(1, sqrt(max throughput)) (checked at the start of shading a vertex, before its NEE).
    c.min_light_bounces = rr_min_bounces(args, depth)
    c.min_transparent_bounces = c.min_light_bounces
    c.sample_clamp_direct = 0.0
    c.sample_clamp_indirect = 0.0
    c.blur_glossy = 0.0
    c.caustics_reflective = True
    c.caustics_refractive = True
    c.light_sampling_threshold = 0.0
    c.pixel_filter_type = "BOX"
    c.filter_width = 1.0
    c.seed = args.seed
    c.use_animated_seed = False
    c.sample_offset = 0
    c.scrambling_distance = 1.0  # 1.0 = no scrambling-distance trick
    c.auto_scrambling_distance = False
    c.use_layer_samples = "IGNORE"
    c.use_auto_tile = False  # one tile for the whole image
    c.debug_use_spatial_splits = False
    if hasattr(c, "use_guiding"):
        c.use_guiding = False

    vs = scene.view_settings
    scene.display_settings.display_device = "sRGB"
    vs.view_transform = "Standard"
    vs.look = "None"
    vs.exposure = 0.0
    vs.gamma = 1.0
    vs.use_curve_mapping = False
    scene.sequencer_colorspace_settings.name = "Linear"

    im = r.image_settings
    im.file_format = "OPEN_EXR"
    im.color_depth = "32"
    im.color_mode = "RGBA" if args.rgba else "RGB"
    im.exr_codec = args.exr_codec
    im.use_preview = False
    r.filepath = os.path.abspath(args.out)
    return depth


class Timer:
    """Timestamps from render handlers.

    bpy.app.handlers.render_stats is called synchronously by Blender right after it prints and
    fflush()es each background status line ("Fra:1 Mem:... | Sample k/N"), but in 3.4 the handler
    receives no text (None). So fd 1 is redirected to a temporary file during the render and the
    handler reads the line that was just written (the file's last unterminated line).
    """

    def __init__(self, spp):
        self.spp = spp
        self.final = "Sample %d/%d" % (spp, spp)
        self.fd = None
        self.t_pre = self.t_post = None
        self.t_first_sample = None   # status "Sample 0/N": path tracing starts
        self.t_last_sample = None    # status "Sample N/N": all samples traced
        self.cpu_first_sample = self.cpu_last_sample = None  # process CPU time, same instants
        self.log = []

    def pre(self, *_):
        self.t_pre = time.perf_counter()

    def post(self, *_):
        self.t_post = time.perf_counter()

    def stats(self, *_):
        now = time.perf_counter()
        cpu = time.process_time()
        if self.fd is None:
            return
        size = os.fstat(self.fd).st_size
        n = min(size, 4096)
        line = os.pread(self.fd, n, size - n).rsplit(b"\n", 1)[-1].decode("utf-8", "replace")
        self.log.append((now, line))
        status = line.rsplit("|", 1)[-1].strip()
        if status.startswith("Sample ") and self.t_first_sample is None:
            self.t_first_sample, self.cpu_first_sample = now, cpu
        if status == self.final and self.t_last_sample is None:
            self.t_last_sample, self.cpu_last_sample = now, cpu


def render_captured(timer):
    """Run the render with fd 1 going to a temp file; echo it afterwards."""
    import tempfile
    sys.stdout.flush()
    tmp = tempfile.TemporaryFile(mode="w+b")
    saved = os.dup(1)
    os.dup2(tmp.fileno(), 1)
    timer.fd = tmp.fileno()
    try:
        bpy.ops.render.render(write_still=True)
    finally:
        sys.stdout.flush()
        timer.fd = None
        os.dup2(saved, 1)
        os.close(saved)
    tmp.seek(0)
    sys.stdout.write(tmp.read().decode("utf-8", "replace"))
    sys.stdout.flush()
    tmp.close()


def exr_string_attributes(path):
    """Plain-Python read of an OpenEXR header's string attributes (e.g. Cycles' own timings,
    cycles.<ViewLayer>.render_time / synchronization_time, written with 10 ms resolution)."""
    import struct
    attrs = {}
    with open(path, "rb") as f:
        data = f.read(65536)
    if data[:4] != b"\x76\x2f\x31\x01":
        return attrs
    i = 8
    try:
        while data[i] != 0:
            j = data.index(b"\0", i)
            k = data.index(b"\0", j + 1)
            size = struct.unpack("<i", data[k + 1:k + 5])[0]
            if data[j + 1:k] == b"string":
                attrs[data[i:j].decode()] = data[k + 5:k + 5 + size].decode("utf-8", "replace")
            i = k + 5 + size
    except (ValueError, IndexError, struct.error):
        pass
    return attrs


def timecode_seconds(s):
    # Blender timecode "MM:SS.ss" or "HH:MM:SS.ss"
    try:
        parts = [float(x) for x in s.split(":")]
    except (AttributeError, ValueError):
        return float("nan")
    t = 0.0
    for x in parts:
        t = t * 60.0 + x
    return t


def image_mean(path):
    img = bpy.data.images.load(os.path.abspath(path), check_existing=False)
    img.colorspace_settings.name = "Linear"  # raw float data, no conversion
    w, h = img.size
    buf = array.array("f", bytes(4 * 4 * w * h))
    img.pixels.foreach_get(buf)
    sr = sum(buf[0::4]) / (w * h)
    sg = sum(buf[1::4]) / (w * h)
    sb = sum(buf[2::4]) / (w * h)
    bpy.data.images.remove(img)
    return (w, h), (sr, sg, sb)


def main():
    args = parse_args()
    ntris = build_scene(args)
    depth = configure(args)
    scene = bpy.context.scene
    out_dir = os.path.dirname(os.path.abspath(args.out))
    os.makedirs(out_dir, exist_ok=True)

    timer = Timer(args.spp)
    bpy.app.handlers.render_pre.append(timer.pre)
    bpy.app.handlers.render_post.append(timer.post)
    bpy.app.handlers.render_stats.append(timer.stats)

    rr_min = rr_min_bounces(args, depth)
    print("CYCLES_CONFIG blender=%s tris=%d spp=%d max_bounces=%d rr=%s threads=%d filter=BOX/1px "
          "seed=%d codec=%s" % (bpy.app.version_string, ntris, args.spp, depth,
                                "off" if rr_min >= depth else "after_%d_bounces" % rr_min,
                                args.threads, args.seed, args.exr_codec), flush=True)
    t0 = time.perf_counter()
    render_captured(timer)
    t1 = time.perf_counter()

    if timer.t_first_sample is None or timer.t_last_sample is None:
        print("CYCLES_WARNING no 'Sample 0/N' .. 'Sample N/N' status seen; render_seconds falls "
              "back to render_pre->render_post", flush=True)
        render_s = (timer.t_post or t1) - (timer.t_pre or t0)
        sync_s = cpu_s = float("nan")
    else:
        render_s = timer.t_last_sample - timer.t_first_sample
        sync_s = timer.t_first_sample - timer.t_pre
        cpu_s = timer.cpu_last_sample - timer.cpu_first_sample
    total_s = (timer.t_post or t1) - (timer.t_pre or t0)

    if args.png:
        rr = bpy.data.images.get("Render Result")
        im = scene.render.image_settings
        im.file_format = "PNG"
        im.color_depth = "8"
        im.color_mode = "RGB"
        rr.save_render(os.path.abspath(args.png), scene=scene)

    (w, h), mean = image_mean(args.out)
    if (w, h) != (args.width, args.height):
        print("CYCLES_WARNING exr size %dx%d != requested %dx%d" % (w, h, args.width, args.height))
    ns = render_s * 1e9 / (args.spp * args.width * args.height)
    print("CYCLES_TIME render_seconds=%.6f sync_seconds=%.6f spp=%d width=%d height=%d threads=%d "
          "depth=%d" % (render_s, sync_s, args.spp, args.width, args.height, args.threads,
                        args.max_depth), flush=True)
    meta = exr_string_attributes(args.out)
    cy_render = next((v for k, v in meta.items() if k.endswith(".render_time")), "")
    cy_sync = next((v for k, v in meta.items() if k.endswith(".synchronization_time")), "")
    print("CYCLES_TIME_DETAIL total_seconds=%.6f render_call_seconds=%.6f ns_per_sample_pixel=%.3f "
          "render_cpu_seconds=%.6f max_bounces=%d cycles_render_time=%.2f cycles_sync_time=%.2f"
          % (total_s, t1 - t0, ns, cpu_s, depth, timecode_seconds(cy_render),
             timecode_seconds(cy_sync)), flush=True)
    print("CYCLES_MEAN %.6f %.6f %.6f" % mean, flush=True)
    if os.environ.get("CYCLES_STATS_LOG"):
        with open(os.environ["CYCLES_STATS_LOG"], "w") as f:
            for t, l in timer.log:
                f.write("%.6f %s\n" % (t - timer.t_pre, l))


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
