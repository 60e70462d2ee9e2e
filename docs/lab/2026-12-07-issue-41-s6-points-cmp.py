# Issue 41 s6: Cycles MULTI_GGX against drift's single BRDF values (luminance of f cos), per row and
# per group. Run: python3 THIS cycles.json drift.jsonl gold|white
import json, sys, math, collections
cy = {(x['col'],x['r'],x['dist'],x['to'],x['ti'],x['ph']): x['rgb'] for x in json.load(open(sys.argv[1] if len(sys.argv)>1 else 'cycles.json'))}
L = lambda v: 0.2126*v[0]+0.7152*v[1]+0.0722*v[2]
rows = [json.loads(l) for l in open(sys.argv[2] if len(sys.argv)>2 else 'drift.jsonl')]
col = sys.argv[3] if len(sys.argv)>3 else 'gold'
print("col r   to ti  ph | cycMS    drift   d/c  | cycSSan  drSS   | cycWalk(MS-SSan) drMS  ms d/c")
grp = collections.defaultdict(list)
for d in rows:
    if d['col'] != col: continue
    k = (d['col'], d['r'], 'MULTI_GGX', d['to'], d['ti'], d['ph'])
    if k not in cy: continue
    cm = L(cy[k]); dt = L(d['drift']); sc = L(d['ss_cyc']); sd = L(d['ss_drift'])
    walk = cm - sc; dms = dt - sd
    print("%s %.1f %3d %2d %3d | %.5f %.5f %.3f | %.5f %.5f | %.5f %.5f %.2f" % (d['col'][0], d['r'], d['to'], d['ti'], d['ph'], cm, dt, dt/cm, sc, sd, walk, dms, dms/walk if walk > 1e-6 else float('nan')))
    grp[(d['r'], 'plane' if d['ph'] == 180 else 'off')].append(math.log(dt/cm))
for k, v in sorted(grp.items()):
    print(k, "n %d rms log %.3f min %.3f max %.3f" % (len(v), math.sqrt(sum(x*x for x in v)/len(v)), math.exp(min(v)), math.exp(max(v))))
