# scalerow.py IN OUT OBJ y:s,y:s...: scale rows of OBJ's pixels (experiment: the bias removed)
import sys
import os; sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import importlib; exr=importlib.import_module('2026-12-07-issue-41-s6-exr'); exrw = importlib.import_module('2026-12-07-issue-41-s7-exrw')
(M,_,_),w,h=exr.load('/tmp/ggx6/masks_sph/mask_%s.exr'%sys.argv[3])
C,_,_=exr.load(sys.argv[1])
for ys in sys.argv[4].split(','):
  y,s=ys.split(':'); y=int(y); s=float(s)
  for c in range(3):
    for x in range(w):
      if M[y][x]>0: C[c][y][x]*=s
exrw.write(sys.argv[2],*C)
