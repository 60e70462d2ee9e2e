# glb variants for isolating lights: nopoint (point light removed), nopanel (panel emission 0)
import json,struct,sys
src,mode,dst=sys.argv[1:4]
b=open(src,'rb').read()
l=struct.unpack('<I',b[12:16])[0]
j=json.loads(b[20:20+l]); rest=b[20+l:]
if mode=='nopoint':
    j['nodes'][0].pop('extensions'); j['nodes'][0]['name']='Empty'
elif mode=='nopanel':
    m=[m for m in j['materials'] if m['name']=='Panel'][0]
    m['emissiveFactor']=[0,0,0]; m.pop('extensions',None)
s=json.dumps(j).encode(); s+=b' '*((4-len(s)%4)%4)
out=struct.pack('<III',0x46546C67,2,12+8+len(s)+len(rest))+struct.pack('<I',len(s))+b'JSON'+s+rest
open(dst,'wb').write(out)
