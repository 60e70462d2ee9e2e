# scalech.py IN OUT OBJ sr sg sb: scale OBJ's mask pixels' channels (experiment)
import sys
import os; sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import importlib; exr=importlib.import_module('2026-12-07-issue-41-s6-exr'); exrw = importlib.import_module('2026-12-07-issue-41-s7-exrw')
(M,_,_),w,h=exr.load('/tmp/ggx6/masks_sph/mask_%s.exr'%sys.argv[3])
C,_,_=exr.load(sys.argv[1]); s=[float(v) for v in sys.argv[4:7]]
for c in range(3):
  for y in range(h):
    for x in range(w):
      if M[y][x]>0: C[c][y][x]*=1+(s[c]-1)*min(M[y][x],1)
exrw.write(sys.argv[2],*C)
