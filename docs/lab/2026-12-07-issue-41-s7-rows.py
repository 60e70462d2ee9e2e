# rows.py OBJ REF TEST [TEST2 ...]: per row of OBJ's mask, mean luminance of REF and TEST/REF ratio
import sys
import os; sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import importlib; exr = importlib.import_module('2026-12-07-issue-41-s6-exr')
def lum(f):
    (R,G,B),w,h = exr.load(f)
    return [[0.2126*R[y][x]+0.7152*G[y][x]+0.0722*B[y][x] for x in range(w)] for y in range(h)]
obj=sys.argv[1]; M,w,h=exr.load('/tmp/ggx6/masks_sph/mask_%s.exr'%obj); M=M[0]
imgs=[lum(f) for f in sys.argv[2:]]
tot=[0]*len(imgs)
for y in range(h):
    xs=[x for x in range(w) if M[y][x]>=0.5]
    if not xs: continue
    s=[sum(im[y][x] for x in xs)/len(xs) for im in imgs]
    for i in range(len(s)): tot[i]+=s[i]*len(xs)
    print('row %2d n %2d ref %.4f '%(y,len(xs),s[0]) + ' '.join('%.3f'%(v/s[0] if s[0]>0 else 0) for v in s[1:]))
print('total ref %.4f '%tot[0] + ' '.join('%.3f'%(v/tot[0]) for v in tot[1:]))
