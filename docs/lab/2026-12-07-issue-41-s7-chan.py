# chan.py OBJ REF TEST...: per-channel mean over OBJ's mask, TEST/REF
import sys
import os; sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import importlib; exr=importlib.import_module('2026-12-07-issue-41-s6-exr')
obj=sys.argv[1]; (M,_,_),w,h=exr.load('/tmp/ggx6/masks_sph/mask_%s.exr'%obj)
px=[(y,x) for y in range(h) for x in range(w) if M[y][x]>=0.5]
def m(f):
    C,_,_=exr.load(f); return [sum(C[c][y][x] for y,x in px)/len(px) for c in range(3)]
r=m(sys.argv[2]); print('ref', ' '.join('%.4f'%v for v in r))
for f in sys.argv[3:]:
    t=m(f); print(f.split('/')[-1], ' '.join('%.3f'%(a/b) for a,b in zip(t,r)))
