# px.py OBJ ROWS REF TEST...: per pixel of the listed rows of OBJ, REF rgb and TEST/REF per channel
import sys
import os; sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import importlib; exr=importlib.import_module('2026-12-07-issue-41-s6-exr')
obj=sys.argv[1]; rows=[int(v) for v in sys.argv[2].split(',')]
(M,_,_),w,h=exr.load('/tmp/ggx6/masks_sph/mask_%s.exr'%obj)
ims=[exr.load(f)[0] for f in sys.argv[3:]]
for y in rows:
  xs=[x for x in range(w) if M[y][x]>=0.5]
  print('row',y)
  for x in xs:
    r=[ims[0][c][y][x] for c in range(3)]
    print('  x %2d ref %.3f %.3f %.3f |'%(x,*r), ' | '.join(' '.join('%.3f'%(im[c][y][x]/r[c]) for c in range(3)) for im in ims[1:]))
