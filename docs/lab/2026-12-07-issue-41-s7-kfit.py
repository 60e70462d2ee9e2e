import json,sys,math,collections
L=lambda v:0.2126*v[0]+0.7152*v[1]+0.0722*v[2]
R=float(sys.argv[2])
cy={}
for f in ['/tmp/ggx6/pts/cycles.json','/tmp/ggx6/pts2/cycles2.json','/tmp/ggx6/pts3/cycles3.json']:
  for x in json.load(open(f)):
    if x['col']=='gold' and x['dist']=='MULTI_GGX' and x['r']==R and x['to']>0 and x['ti']>0: cy[(x['to'],x['ti'],x['ph'])]=L(x['rgb'])
g=collections.defaultdict(list)
for l in open(sys.argv[1]):
  d=json.loads(l); q=(d['to'],d['ti'],d['ph'])
  if q in cy and abs(d['r']-R)<1e-3: g[(d['k'],d['beta'],d['p'])].append((d,cy[q]))
def reg(d):
  if d['to']<=60 and d['ti']<=60: return 'mod'
  if d['to']>=70 and d['ti']>=70: return 'graz'
  return 'mix'
out=[]
for key,v in g.items():
  e=collections.defaultdict(list)
  for d,c in v:
    x=math.log((d['ss']+d['lobe'])/c); e['all'].append(x); e[reg(d)].append(x)
  a=e['all']; out.append((math.sqrt(sum(x*x for x in a)/len(a)),key,math.exp(min(a)),math.exp(max(a)),{k:(sum(x)/len(x)) for k,x in e.items()}))
out.sort()
for o in out[:int(sys.argv[3]) if len(sys.argv)>3 else 8]: print('k %g beta %g p %g: rms %.3f [%.3f-%.3f] '%(*o[1],o[0],o[2],o[3])+' '.join('%s %+.3f'%(k,v) for k,v in sorted(o[4].items())))
