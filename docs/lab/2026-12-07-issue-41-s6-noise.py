# noise.py SCENE MASKDIR PREFIX...: per object, mean over its pixels of the across-seed std of
# luminance / the mean luminance there (4 seeds at 256 spp), per image set.
import sys, glob, math
import importlib; exr = importlib.import_module('2026-12-07-issue-41-s6-exr')
S = sys.argv[1]
def lum(f):
    (R, G, B), w, h = exr.load(f)
    return [[0.2126*R[y][x]+0.7152*G[y][x]+0.0722*B[y][x] for x in range(w)] for y in range(h)], w, h
masks = {m.split('mask_')[1][:-4]: exr.load(m) for m in sorted(glob.glob('/tmp/ggx6/masks_%s/mask_*.exr' % S))}
for pre in sys.argv[2:]:
    imgs = [lum(f)[0] for f in sorted(glob.glob('/tmp/ggx6/%s_%s_256_s*.exr' % (pre, S)))]
    out = []
    for name, ((R, _, _), w, h) in masks.items():
        if name == 'Panel': continue
        px = [(y, x) for y in range(h) for x in range(w) if R[y][x] >= 0.5]
        n = len(imgs); sd = 0; mean = 0
        for y, x in px:
            v = [im[y][x] for im in imgs]; m = sum(v)/n
            sd += math.sqrt(sum((a-m)**2 for a in v)/(n-1)); mean += m
        out.append('%s %.3f' % (name, sd/mean))
    print(pre, len(imgs), 'seeds: rel. std', ' | '.join(out))
