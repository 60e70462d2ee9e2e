# Issue 41 s6: single BRDF values of Cycles 3.4's Principled metal (MULTI_GGX and GGX) under a
# sun on a 1000 m plane, orthographic 8x8 camera at theta_o, max bounces 0 (s3's method).
import bpy, math, sys, json
from mathutils import Vector
out = sys.argv[sys.argv.index('--')+1]
bpy.ops.wm.read_factory_settings(use_empty=True)
sc = bpy.context.scene
sc.render.engine = 'CYCLES'; sc.cycles.device = 'CPU'; sc.cycles.samples = 256
sc.cycles.use_adaptive_sampling = False; sc.cycles.use_denoising = False; sc.cycles.max_bounces = 0
sc.render.threads_mode = 'FIXED'; sc.render.threads = 2
sc.render.resolution_x = 8; sc.render.resolution_y = 8
sc.render.image_settings.file_format = 'OPEN_EXR'; sc.render.image_settings.color_depth = '32'
sc.view_settings.view_transform = 'Standard'
w = bpy.data.worlds.new('w'); w.use_nodes = True
w.node_tree.nodes['Background'].inputs[1].default_value = 0.0; sc.world = w
bpy.ops.mesh.primitive_plane_add(size=1000); pl = bpy.context.object
mat = bpy.data.materials.new('m'); mat.use_nodes = True
pb = mat.node_tree.nodes['Principled BSDF']; pl.data.materials.append(mat)
cd = bpy.data.cameras.new('c'); cd.type = 'ORTHO'; cd.ortho_scale = 0.2
cam = bpy.data.objects.new('c', cd); sc.collection.objects.link(cam); sc.camera = cam
ld = bpy.data.lights.new('s', 'SUN'); ld.energy = 1.0; ld.angle = 0.0
sun = bpy.data.objects.new('s', ld); sc.collection.objects.link(sun)
def d(t, p):
    t = math.radians(t); p = math.radians(p)
    return Vector((math.sin(t)*math.cos(p), math.sin(t)*math.sin(p), math.cos(t)))
res = []
for col_name, col in (('gold', (1.0, 0.78, 0.34)), ('white', (1, 1, 1))):
  for r in (0.8, 0.5):
    for dist in ('MULTI_GGX', 'GGX'):
      for to in (85, 80, 70):
        for ti in (85, 80, 70, 60, 30):
          for ph in (180, 135, 90, 45, 0):
            pb.distribution = dist
            pb.inputs['Base Color'].default_value = (*col, 1)
            pb.inputs['Metallic'].default_value = 1.0
            pb.inputs['Roughness'].default_value = r
            pb.inputs['IOR'].default_value = 1.5
            pb.inputs['Specular'].default_value = 0.5
            wo = d(to, 0); cam.location = wo * 10
            cam.rotation_euler = wo.to_track_quat('Z', 'Y').to_euler()
            sun.rotation_euler = d(ti, ph).to_track_quat('Z', 'Y').to_euler()
            sc.render.filepath = out + '/tmp.exr'
            bpy.ops.render.render(write_still=True)
            im = bpy.data.images.load(out + '/tmp.exr')
            px = list(im.pixels); n = len(px)//4
            m = [sum(px[4*i+c] for i in range(n))/n for c in range(3)]
            bpy.data.images.remove(im)
            res.append(dict(col=col_name, r=r, dist=dist, to=to, ti=ti, ph=ph, rgb=m))
json.dump(res, open(out + '/cycles.json', 'w'), indent=0)
