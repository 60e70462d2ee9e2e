# noisepx.py OBJ PREFIX...: per-object rel std over 4 seeds (as s6 noise.py), the 3 noisiest pixels, and rel std without the noisiest
import sys,glob,math
import os; sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import importlib; exr=importlib.import_module('2026-12-07-issue-41-s6-exr')
obj=sys.argv[1]; (M,_,_),w,h=exr.load('/tmp/ggx6/masks_sph/mask_%s.exr'%obj)
px=[(y,x) for y in range(h) for x in range(w) if M[y][x]>=0.5]
def lum(f):
    (R,G,B),_,_=exr.load(f); return [[0.2126*R[y][x]+0.7152*G[y][x]+0.0722*B[y][x] for x in range(w)] for y in range(h)]
for pre in sys.argv[2:]:
    ims=[lum(f) for f in sorted(glob.glob(pre+'_sph_256_s*.exr'))]; n=len(ims)
    st=[]
    for y,x in px:
        v=[im[y][x] for im in ims]; m=sum(v)/n; st.append((math.sqrt(sum((a-m)**2 for a in v)/(n-1)),m,y,x))
    S=sum(s for s,_,_,_ in st); Mn=sum(m for _,m,_,_ in st); st.sort(reverse=True)
    print(pre.split('/')[-1],'rel std %.3f'%(S/Mn),'without the noisiest pixel %.3f'%((S-st[0][0])/(Mn-st[0][1])),'top:',' '.join('(%d,%d) std %.2f mean %.2f'%(y,x,s,m) for s,m,y,x in st[:3]))
