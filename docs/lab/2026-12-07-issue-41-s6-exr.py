# Issue 41 s6: an EXR reader (bench/cycles/exr_mean.py's decoder) returning ([R, G, B] rows, w, h).
import sys, struct, zlib
import os; sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), '../../bench/cycles'))
from exr_mean import read_header, undo_zip, LINES_PER_BLOCK, PIXEL_SIZE, PIXEL_FMT
def load(path):
    d = open(path, 'rb').read(); hdr, pos = read_header(d); comp = hdr['compression']
    x0, y0, x1, y1 = hdr['dataWindow']; w, h = x1-x0+1, y1-y0+1; chans = hdr['channels']
    lpb = LINES_PER_BLOCK[comp]; nb = (h+lpb-1)//lpb
    offs = struct.unpack('<%dQ' % nb, d[pos:pos+8*nb]); img = {c[0]: [[0]*w for _ in range(h)] for c in chans}
    for off in offs:
        y, size = struct.unpack('<ii', d[off:off+8]); data = d[off+8:off+8+size]; nl = min(lpb, y1-y+1)
        expect = nl*w*sum(PIXEL_SIZE[t] for _, t, _, _ in chans)
        if comp != 0 and size < expect: data = undo_zip(zlib.decompress(data))
        p = 0
        for l in range(nl):
            for name, t, _, _ in chans:
                n = PIXEL_SIZE[t]*w; img[name][y-y0+l] = list(struct.unpack('<%d%s' % (w, PIXEL_FMT[t]), data[p:p+n])); p += n
    def pick(c):
        for k in img:
            if k == c or k.endswith('.'+c): return img[k]
    return [pick('R'), pick('G'), pick('B')], w, h
