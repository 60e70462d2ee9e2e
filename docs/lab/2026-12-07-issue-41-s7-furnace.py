# Cycles 3.4 white furnace: a white (or gold) Principled metal sphere, uniform white world of strength 1,
# orthographic camera, max bounces 0 (a convex sphere sees only the world): each pixel is the
# directional albedo at mu = cos(angle between view and normal). Args: OUT r dist col(white|gold) spp
import bpy, sys, math, array
a = sys.argv[sys.argv.index('--')+1:]
out, r, dist, col, spp = a[0], float(a[1]), a[2], a[3], int(a[4])
bpy.ops.wm.read_factory_settings(use_empty=True)
sc = bpy.context.scene
sc.render.engine = 'CYCLES'; c = sc.cycles; c.device = 'CPU'; c.samples = spp; c.seed = 1
c.use_adaptive_sampling = False; c.use_denoising = False
c.max_bounces = 0; c.sample_clamp_direct = c.sample_clamp_indirect = 0
c.pixel_filter_type = 'BOX'; c.filter_width = 1.0
sc.render.threads_mode = 'FIXED'; sc.render.threads = 2
sc.render.resolution_x = sc.render.resolution_y = 64
sc.render.image_settings.file_format = 'OPEN_EXR'; sc.render.image_settings.color_depth = '32'
sc.render.image_settings.exr_codec = 'NONE'
sc.view_settings.view_transform = 'Standard'
w = bpy.data.worlds.new('w'); w.use_nodes = True
w.node_tree.nodes['Background'].inputs[0].default_value = (1, 1, 1, 1); w.node_tree.nodes['Background'].inputs[1].default_value = 1.0; sc.world = w
bpy.ops.mesh.primitive_uv_sphere_add(radius=1, segments=256, ring_count=128); sp = bpy.context.object
bpy.ops.object.shade_smooth()
m = bpy.data.materials.new('m'); m.use_nodes = True; pb = m.node_tree.nodes['Principled BSDF']
pb.distribution = dist; pb.inputs['Specular'].default_value = 0.5; pb.inputs['Metallic'].default_value = 1.0; pb.inputs['Roughness'].default_value = r
pb.inputs['Base Color'].default_value = (1, 1, 1, 1) if col == 'white' else (1.0, 0.78, 0.34, 1)
sp.data.materials.append(m)
cd = bpy.data.cameras.new('c'); cd.type = 'ORTHO'; cd.ortho_scale = 2.0
cam = bpy.data.objects.new('c', cd); sc.collection.objects.link(cam); sc.camera = cam
cam.location = (0, 0, 10)
sc.render.filepath = out
bpy.ops.render.render(write_still=True)
im = bpy.data.images.load(out); px = array.array('f', im.pixels[:]); W = H = 64
bins = {}
for y in range(H):
    for x in range(W):
        u = (x + 0.5) / W * 2 - 1; v = (y + 0.5) / H * 2 - 1; s2 = u*u + v*v
        if s2 >= 0.97: continue
        mu = math.sqrt(1 - s2); b = min(int(mu * 10), 9)
        bins.setdefault(b, []).append(px[4*(y*W+x)])
print('CORNER %.4f' % px[0]); print('FURNACE', r, dist, col, ' '.join('mu%.2f-%.2f:%.4f(n%d)' % (b/10, (b+1)/10, sum(v)/len(v), len(v)) for b, v in sorted(bins.items())))
