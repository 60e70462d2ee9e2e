# Crops two 64x48 EXRs (ref, test) into five column strips, image rows 16-31, one an object of
# tests/data/ggx/ggx_scene.glb (metals 0.05, 0.25, 0.5, 0.8, glass, left to right), written as
# /tmp/crop_{ref,tst}_N.exr for `drift diff`. Run: blender -b --python THIS -- REF.exr TEST.exr
import bpy, numpy as np, sys
argv = sys.argv[sys.argv.index("--")+1:]
def load(p):
    im = bpy.data.images.load(p); im.pixels[0]; w,h = im.size
    return np.array(im.pixels[:], dtype=np.float32).reshape(h,w,4)  # bottom row first
def save(a, p):
    h,w,_ = a.shape
    im = bpy.data.images.new("c", w, h, alpha=True, float_buffer=True)
    im.pixels[:] = a.ravel().tolist()
    im.filepath_raw = p; im.file_format = 'OPEN_EXR'; im.save()
ref = load(argv[0]); tst = load(argv[1])
rows = (48-32, 48-16)  # image rows 16..31 from the top
for i,(x0,x1) in enumerate([(0,11),(11,25),(25,41),(41,57),(57,64)]):
    for nm,a in (("ref",ref),("tst",tst)):
        save(a[rows[0]:rows[1], x0:x1].copy(), "/tmp/crop_%s_%d.exr"%(nm,i))
