# Luminance ratio drift/Cycles over strip 4 (image rows 16-31, columns 41-56) of two 64x48 EXRs.
# Run: blender -b --python THIS -- CYCLES.exr DRIFT.exr
import bpy, numpy as np, sys
argv = sys.argv[sys.argv.index("--")+1:]
def load(p):
    im = bpy.data.images.load(p); im.pixels[0]; w,h = im.size
    return np.array(im.pixels[:], dtype=np.float32).reshape(h,w,4)[::-1]
c = load(argv[0]); d = load(argv[1])
L = lambda a: 0.2126*a[...,0]+0.7152*a[...,1]+0.0722*a[...,2]
r = L(d)/np.maximum(L(c),1e-4)
np.set_printoptions(linewidth=300, precision=2, suppress=True)
print(r[16:32, 41:57])
print("Cycles lum"); print(L(c)[16:32, 41:57])
