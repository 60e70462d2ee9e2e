# fitw.py comp_all.jsonl: per roughness, rms log(drift/Cycles) of ss + F_ms (w lobe(k) + (1-w) KC) over
# the gold MULTI_GGX rows, for a grid of k and w; best per r, and the current (k(r), w=1)
import json,sys,math,collections
L=lambda v:0.2126*v[0]+0.7152*v[1]+0.0722*v[2]
cy={}
for f in ['/tmp/ggx6/pts/cycles.json','/tmp/ggx6/pts2/cycles2.json','/tmp/ggx6/pts3/cycles3.json']:
  for x in json.load(open(f)):
    if x['col']=='gold' and x['dist']=='MULTI_GGX' and x['to']>0 and x['ti']>0: cy[(round(x['r'],3),x['to'],x['ti'],x['ph'])]=L(x['rgb'])
rows=collections.defaultdict(list)
for l in open(sys.argv[1]):
  d=json.loads(l); key=(round(d['r'],3),d['to'],d['ti'],d['ph'])
  if key in cy: rows[(key[0],d['k'])].append((d,cy[key]))
ws=[1,0.95,0.9,0.85,0.8,0.75,0.7,0.65,0.6,0.5,0.4]
sel=sys.argv[2] if len(sys.argv)>2 else 'all'
for r in sorted(set(k[0] for k in rows)):
  res=[]
  for (rr,k),v in rows.items():
    if rr!=r: continue
    for w in ws:
      e=[]; eo=[]
      for d,c in v:
        if sel=='off' and d['ph']==180: continue
        m=d['ss']+w*d['lobe']+(1-w)*d['kc']; e.append(math.log(m/c))
      res.append((math.sqrt(sum(x*x for x in e)/len(e)),k,w,math.exp(min(e)),math.exp(max(e)),sum(e)/len(e),len(e)))
  res.sort()
  print('r %.2f n %d best:'%(r,res[0][6]),' ; '.join('k %.2f w %.2f rms %.3f [%.2f-%.2f] mean %+.3f'%(x[1],x[2],x[0],x[3],x[4],x[5]) for x in res[:4]))
  t=min(max((r-0.35)/0.65,0),1); kc=2.5+t*(1-2.5)
  cur=[x for x in res if abs(x[1]-kc)<0.13 and x[2]==1]
  print('   current-ish', ' ; '.join('k %.2f w 1 rms %.3f [%.2f-%.2f] mean %+.3f'%(x[1],x[0],x[3],x[4],x[5]) for x in cur))
