# combine.py OUT W1 F1 W2 F2 ...: weighted mean of EXRs
import sys
import os; sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import importlib; exr=importlib.import_module('2026-12-07-issue-41-s6-exr'); exrw = importlib.import_module('2026-12-07-issue-41-s7-exrw')
a=sys.argv[2:]; ws=[float(x) for x in a[0::2]]; fs=a[1::2]; W=sum(ws)
ims=[exr.load(f)[0] for f in fs]; h=len(ims[0][0]); w=len(ims[0][0][0])
C=[[[sum(wt*im[c][y][x] for wt,im in zip(ws,ims))/W for x in range(w)] for y in range(h)] for c in range(3)]
exrw.write(sys.argv[1],*C)
