# minimal uncompressed scanline float32 RGB EXR writer
import struct
def attr(n,t,v): return n.encode()+b'\0'+t.encode()+b'\0'+struct.pack('<i',len(v))+v
def write(path,R,G,B):
    h=len(R); w=len(R[0])
    ch=b''.join(c.encode()+b'\0'+struct.pack('<iBBBBii',2,0,0,0,0,1,1) for c in 'BGR')+b'\0'
    hdr=b'\x76\x2f\x31\x01'+struct.pack('<i',2)
    hdr+=attr('channels','chlist',ch)+attr('compression','compression',b'\0')
    box=struct.pack('<iiii',0,0,w-1,h-1)
    hdr+=attr('dataWindow','box2i',box)+attr('displayWindow','box2i',box)
    hdr+=attr('lineOrder','lineOrder',b'\0')+attr('pixelAspectRatio','float',struct.pack('<f',1))
    hdr+=attr('screenWindowCenter','v2f',struct.pack('<ff',0,0))+attr('screenWindowWidth','float',struct.pack('<f',1))+b'\0'
    start=len(hdr)+8*h; blk=8+12*w; offs=b''.join(struct.pack('<Q',start+y*blk) for y in range(h))
    data=b''
    for y in range(h):
        data+=struct.pack('<ii',y,12*w)
        for C in (B,G,R): data+=struct.pack('<%df'%w,*C[y])
    open(path,'wb').write(hdr+offs+data)
