#!/usr/bin/env python3
"""Mean linear RGB of an OpenEXR image, in plain Python 3 (no numpy, no OpenEXR module).

    python3 bench/cycles/exr_mean.py FILE.exr [FILE2.exr ...]
    -> EXR_MEAN <r> <g> <b> width=<w> height=<h> file=<path>

Supports what the comparison needs: single-part scanline images, channels HALF/FLOAT/UINT,
compression NONE, ZIPS or ZIP. Used by run_compare.sh as an independent check of drift's output
next to `drift diff` (and of the Cycles EXR: it must reproduce CYCLES_MEAN).
"""
import itertools
import struct
import sys
import zlib

COMPRESSION = {0: "NONE", 1: "RLE", 2: "ZIPS", 3: "ZIP", 4: "PIZ", 5: "PXR24", 6: "B44",
               7: "B44A", 8: "DWAA", 9: "DWAB"}
LINES_PER_BLOCK = {0: 1, 2: 1, 3: 16}
PIXEL_SIZE = {0: 4, 1: 2, 2: 4}  # UINT, HALF, FLOAT
PIXEL_FMT = {0: "I", 1: "e", 2: "f"}


def read_header(d):
    if d[:4] != b"\x76\x2f\x31\x01":
        raise ValueError("not an OpenEXR file")
    flags = struct.unpack("<I", d[4:8])[0]
    if flags & 0x200:
        raise ValueError("tiled EXR not supported")
    if flags & 0x1000:
        raise ValueError("multi-part EXR not supported")
    i, hdr = 8, {}
    while d[i] != 0:
        j = d.index(b"\0", i)
        k = d.index(b"\0", j + 1)
        name, typ = d[i:j].decode(), d[j + 1:k].decode()
        size = struct.unpack("<i", d[k + 1:k + 5])[0]
        val = d[k + 5:k + 5 + size]
        if typ == "chlist":
            chans, p = [], 0
            while val[p] != 0:
                q = val.index(b"\0", p)
                ptype, _, _, xs, ys = struct.unpack("<iB3sii", val[q + 1:q + 17])
                chans.append((val[p:q].decode(), ptype, xs, ys))
                p = q + 17
            val = chans
        elif typ == "box2i":
            val = struct.unpack("<4i", val)
        elif typ in ("compression", "lineOrder"):
            val = val[0]
        hdr[name] = val
        i = k + 5 + size
    return hdr, i + 1


def undo_zip(raw):
    t = list(itertools.accumulate(raw, lambda a, b: (a + b - 128) & 0xFF))
    n = len(t)
    half = (n + 1) // 2
    out = bytearray(n)
    out[0::2] = bytes(t[:half])
    out[1::2] = bytes(t[half:])
    return bytes(out)


def exr_mean(path):
    with open(path, "rb") as f:
        d = f.read()
    hdr, pos = read_header(d)
    comp = hdr["compression"]
    if comp not in LINES_PER_BLOCK:
        raise ValueError("compression %s not supported (use NONE/ZIPS/ZIP)" % COMPRESSION.get(comp))
    x0, y0, x1, y1 = hdr["dataWindow"]
    w, h = x1 - x0 + 1, y1 - y0 + 1
    chans = hdr["channels"]  # sorted by name in the file
    if any(xs != 1 or ys != 1 for _, _, xs, ys in chans):
        raise ValueError("subsampled channels not supported")
    lpb = LINES_PER_BLOCK[comp]
    nblocks = (h + lpb - 1) // lpb
    offsets = struct.unpack("<%dQ" % nblocks, d[pos:pos + 8 * nblocks])
    sums = {name: 0.0 for name, _, _, _ in chans}
    for off in offsets:
        y, size = struct.unpack("<ii", d[off:off + 8])
        data = d[off + 8:off + 8 + size]
        nlines = min(lpb, y1 - y + 1)
        expect = nlines * w * sum(PIXEL_SIZE[t] for _, t, _, _ in chans)
        if comp != 0 and size < expect:
            data = undo_zip(zlib.decompress(data))
        p = 0
        for _ in range(nlines):
            for name, ptype, _, _ in chans:
                n = PIXEL_SIZE[ptype] * w
                sums[name] += sum(struct.unpack("<%d%s" % (w, PIXEL_FMT[ptype]), data[p:p + n]))
                p += n

    def pick(*names):
        for n in names:
            for c in sums:
                if c == n or c.endswith("." + n):
                    return sums[c] / (w * h)
        return float("nan")

    return (pick("R", "r"), pick("G", "g"), pick("B", "b")), (w, h)


def main():
    if len(sys.argv) < 2:
        print(__doc__.strip(), file=sys.stderr)
        return 2
    rc = 0
    for path in sys.argv[1:]:
        try:
            (r, g, b), (w, h) = exr_mean(path)
            print("EXR_MEAN %.6f %.6f %.6f width=%d height=%d file=%s" % (r, g, b, w, h, path))
        except (OSError, ValueError, KeyError, zlib.error, struct.error) as e:
            print("EXR_MEAN error file=%s: %s" % (path, e))
            rc = 1
    return rc


if __name__ == "__main__":
    sys.exit(main())
