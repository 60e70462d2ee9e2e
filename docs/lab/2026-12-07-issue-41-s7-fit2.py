# fit2.py comp_all.jsonl: ss + F_ms (w lobe(k1) + (1-w) lobe(k2)) (+ optional KC part c): rms log vs Cycles
import json,sys,math,collections,itertools
L=lambda v:0.2126*v[0]+0.7152*v[1]+0.0722*v[2]
cy={}
for f in ['/tmp/ggx6/pts/cycles.json','/tmp/ggx6/pts2/cycles2.json','/tmp/ggx6/pts3/cycles3.json']:
  for x in json.load(open(f)):
    if x['col']=='gold' and x['dist']=='MULTI_GGX' and x['to']>0 and x['ti']>0: cy[(round(x['r'],3),x['to'],x['ti'],x['ph'])]=L(x['rgb'])
lob=collections.defaultdict(dict); base={}
for l in open(sys.argv[1]):
  d=json.loads(l); key=(round(d['r'],3),d['to'],d['ti'],d['ph'])
  if key in cy: lob[key][d['k']]=d['lobe']; base[key]=d
for r in sorted(set(k[0] for k in base)):
  keys=[k for k in base if k[0]==r]; ks=sorted(lob[keys[0]])
  res=[]
  for k1,k2 in itertools.combinations_with_replacement(ks,2):
    for w in [1,0.9,0.8,0.7,0.6,0.5,0.4,0.3,0.2]:
      for c in [0,0.05,0.1,0.2]:
        e=[math.log((base[q]['ss']+(1-c)*(w*lob[q][k1]+(1-w)*lob[q][k2])+c*base[q]['kc'])/cy[q]) for q in keys]
        res.append((math.sqrt(sum(x*x for x in e)/len(e)),k1,k2,w,c,math.exp(min(e)),math.exp(max(e))))
  res.sort()
  print('r %.2f'%r, ' ; '.join('k %g/%g w %.1f kc %.2f rms %.3f [%.2f-%.2f]'%(x[1],x[2],x[3],x[4],x[0],x[5],x[6]) for x in res[:3]))
