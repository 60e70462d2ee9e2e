# rowmasks.py OBJ: per-row masks of OBJ into /tmp/metal/rm/OBJ_rowY.exr; also /tmp/metal/rm/OBJ_top.exr (rows listed in argv[2:])
import sys,os
import os; sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import importlib; exr=importlib.import_module('2026-12-07-issue-41-s6-exr'); exrw = importlib.import_module('2026-12-07-issue-41-s7-exrw')
obj=sys.argv[1]; (M,_,_),w,h=exr.load('/tmp/ggx6/masks_sph/mask_%s.exr'%obj)
os.makedirs('/tmp/metal/rm',exist_ok=True)
for y in range(h):
    if not any(M[y][x]>=0.5 for x in range(w)): continue
    Z=[[ (1.0 if (yy==y and M[yy][x]>=0.5) else 0.0) for x in range(w)] for yy in range(h)]
    exrw.write('/tmp/metal/rm/%s_row%02d.exr'%(obj,y),Z,Z,Z)
