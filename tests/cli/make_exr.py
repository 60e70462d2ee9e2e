# An uncompressed scanline RGB EXR written by hand (no OpenEXR needed): the CLI tests use it
# for images drift's own writer would refuse to make (NaN pixels, exact values).
#   exr(path, width, height, pixel) with pixel(x, y) -> (r, g, b)
import struct


def attr(name, typ, data):
    return name.encode() + b"\0" + typ.encode() + b"\0" + struct.pack("<i", len(data)) + data
def exr(path, w, h, pixel):
    ch = b"".join(n.encode() + b"\0" + struct.pack("<iBBBBii", 2, 0, 0, 0, 0, 1, 1) for n in "BGR")
    hdr = b"\x76\x2f\x31\x01" + struct.pack("<i", 2) + attr("channels", "chlist", ch + b"\0")
    hdr += attr("compression", "compression", b"\0")
    hdr += attr("dataWindow", "box2i", struct.pack("<iiii", 0, 0, w - 1, h - 1))
    hdr += attr("displayWindow", "box2i", struct.pack("<iiii", 0, 0, w - 1, h - 1))
    hdr += attr("lineOrder", "lineOrder", b"\0")
    hdr += attr("pixelAspectRatio", "float", struct.pack("<f", 1.0))
    hdr += attr("screenWindowCenter", "v2f", struct.pack("<ff", 0, 0))
    hdr += attr("screenWindowWidth", "float", struct.pack("<f", 1.0)) + b"\0"
    chunks = []
    for y in range(h):
        data = b"".join(struct.pack("<%df" % w, *[pixel(x, y)[c] for x in range(w)])
                        for c in (2, 1, 0))
        chunks.append(struct.pack("<ii", y, len(data)) + data)
    off, table = len(hdr) + 8 * h, b""
    for c in chunks:
        table += struct.pack("<Q", off)
        off += len(c)
    open(path, "wb").write(hdr + table + b"".join(chunks))
