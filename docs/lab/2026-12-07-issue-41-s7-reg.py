import json,sys,math,collections
L=lambda v:0.2126*v[0]+0.7152*v[1]+0.0722*v[2]
cy={}
for f in ['/tmp/ggx6/pts/cycles.json','/tmp/ggx6/pts3/cycles3.json']:
  for x in json.load(open(f)):
    if x['col']=='gold' and x['dist']=='MULTI_GGX' and x['r']==0.8 and x['to']>0 and x['ti']>0: cy[(x['to'],x['ti'],x['ph'])]=L(x['rgb'])
rows=collections.defaultdict(list)
for l in open(sys.argv[1]):
  d=json.loads(l)
  if round(d['r'],3)!=0.8: continue
  k=(d['to'],d['ti'],d['ph'])
  if k in cy: rows[d['k']].append((d,cy[k]))
def reg(d):
  if d['to']<=60 and d['ti']<=60: return 'mod'
  if d['to']>=70 and d['ti']>=70: return 'graz'
  return 'mix'
for k in sorted(rows):
  for c in [0,0.1,0.2,0.3,0.5]:
    e=collections.defaultdict(list)
    for d,v in rows[k]:
      x=math.log((d['ss']+(1-c)*d['lobe']+c*d['kc'])/v); e[reg(d)].append(x); e['all'].append(x)
    print('k %.2f c %.1f '%(k,c)+' '.join('%s %+.3f/%.3f'%(g,sum(v)/len(v),math.sqrt(sum(y*y for y in v)/len(v))) for g,v in sorted(e.items())))
