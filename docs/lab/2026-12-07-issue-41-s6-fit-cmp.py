# Issue 41 s6: rms log(drift / Cycles) per roughness and k of fit.c's rows. Run: python3 THIS fit.jsonl cycles.json [cycles2.json]
import json, sys, math, collections
cy = {}
for f in sys.argv[2:]:
    for x in json.load(open(f)):
        if x['col'] == 'gold' and x['dist'] == 'MULTI_GGX': cy[(round(x['r'],3), x['to'], x['ti'], x['ph'])] = x['rgb']
L = lambda v: 0.2126*v[0]+0.7152*v[1]+0.0722*v[2]
e = collections.defaultdict(list)
for l in open(sys.argv[1]):
    d = json.loads(l); k = (round(d['r'],3), d['to'], d['ti'], d['ph'])
    if k not in cy: continue
    x = math.log(L(d['tot'])/L(cy[k]))
    e[(d['r'], d['k'], 'all')].append(x); e[(d['r'], d['k'], 'plane' if d['ph']==180 else 'off')].append(x)
for k, v in sorted(e.items()):
    print(k, "rms log %.3f  range %.3f-%.3f" % (math.sqrt(sum(x*x for x in v)/len(v)), math.exp(min(v)), math.exp(max(v))))
