#!/usr/bin/env python3
"""Mean luminance of each quarter of the image's width in the sphere band (rows 14-34 of 48,
top down) of the clearcoat scene's renders: the bare, coat 0.05, coat 0.3 and coated-metal
spheres, for issue 41's comparison with Cycles (docs/lab/2026-12-07-issue-41-s4b.md).

    python3 tests/data/clearcoat/sphere_means.py REF.exr TEST.exr [...]
"""
import os
import struct
import sys
import zlib

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "../../../bench/cycles"))
import exr_mean as em  # noqa: E402


def pixels(path):
    d = open(path, "rb").read()
    hdr, pos = em.read_header(d)
    comp = hdr["compression"]
    x0, y0, x1, y1 = hdr["dataWindow"]
    w, h = x1 - x0 + 1, y1 - y0 + 1
    chans = hdr["channels"]
    lpb = em.LINES_PER_BLOCK[comp]
    nblocks = (h + lpb - 1) // lpb
    offsets = struct.unpack("<%dQ" % nblocks, d[pos:pos + 8 * nblocks])
    img = {name: [[0.0] * w for _ in range(h)] for name, _, _, _ in chans}
    for off in offsets:
        y, size = struct.unpack("<ii", d[off:off + 8])
        data = d[off + 8:off + 8 + size]
        nlines = min(lpb, y1 - y + 1)
        expect = nlines * w * sum(em.PIXEL_SIZE[t] for _, t, _, _ in chans)
        if comp != 0 and size < expect:
            data = em.undo_zip(zlib.decompress(data))
        p = 0
        for line in range(nlines):
            for name, ptype, _, _ in chans:
                n = em.PIXEL_SIZE[ptype] * w
                img[name][y - y0 + line] = list(
                    struct.unpack("<%d%s" % (w, em.PIXEL_FMT[ptype]), data[p:p + n]))
                p += n

    def pick(n):
        return next(v for c, v in img.items() if c == n or c.endswith("." + n))
    return pick("R"), pick("G"), pick("B"), w, h


def quarters(path):
    r, g, b, w, h = pixels(path)
    out = []
    for q in range(4):
        s, n = 0.0, 0
        for y in range(h * 14 // 48, h * 34 // 48):
            for x in range(q * w // 4, (q + 1) * w // 4):
                s += 0.2126 * r[y][x] + 0.7152 * g[y][x] + 0.0722 * b[y][x]
                n += 1
        out.append(s / n)
    return out


ref = quarters(sys.argv[1])
print("%-40s" % os.path.basename(sys.argv[1]), " ".join("%.4f" % v for v in ref))
for f in sys.argv[2:]:
    q = quarters(f)
    print("%-40s" % os.path.basename(f), " ".join("%.4f" % v for v in q), " ratio",
          " ".join("%.3f" % (a / b) for a, b in zip(q, ref)))
