#!/usr/bin/env bash
# CLI tests for `drift diff`: exit codes, plain and --json output, --difftol, --heatmap, and
# clear failures for missing, corrupt and mismatched inputs. $1 is the drift binary.
set -u
drift="$1"
source "$(dirname "$0")/common.sh"

# Inputs are small PNGs written with python3's zlib and struct (no image tools needed).
python3 - "$tmp" <<'PY'
import struct, sys, zlib
def png(path, w, h, pixel):
    raw = b"".join(b"\x00" + b"".join(bytes(pixel(x, y)) for x in range(w)) for y in range(h))
    def chunk(t, d):
        c = struct.pack(">I", len(d)) + t + d
        return c + struct.pack(">I", zlib.crc32(t + d) & 0xffffffff)
    data = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
    data += chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b"")
    open(path, "wb").write(data)
d = sys.argv[1]
png(d + "/ref.png", 32, 24, lambda x, y: (x * 8, y * 10, 128))
png(d + "/test.png", 32, 24, lambda x, y: (x * 8, y * 10, 128 if (x + y) % 7 else 160))
png(d + "/small.png", 16, 24, lambda x, y: (0, 0, 0))
open(d + "/corrupt.png", "wb").write(open(d + "/ref.png", "rb").read()[:60])
open(d + "/garbage.exr", "wb").write(b"not an exr file" * 10)
PY

# Help and usage.
expect 0 "$drift" diff --help
grep -q "usage: drift diff" "$tmp/out" || fail "--help prints usage on stdout"
expect 2 "$drift" diff
expect 2 "$drift" diff "$tmp/ref.png"
expect 2 "$drift" diff "$tmp/ref.png" "$tmp/test.png" --bogus
expect 2 "$drift" diff "$tmp/ref.png" "$tmp/test.png" --ppd nope
expect 2 "$drift" diff "$tmp/ref.png" "$tmp/test.png" --difftol

# Identical images: zero error; psnr is null in JSON and "inf" in plain output.
expect 0 "$drift" diff "$tmp/ref.png" "$tmp/ref.png"
for key in mse rmse relmse psnr ssim flip; do
    grep -q "^$key " "$tmp/out" || fail "plain output has a '$key' line"
done
grep -q "^psnr *inf$" "$tmp/out" || fail "plain psnr of identical images is inf"
expect 0 "$drift" diff "$tmp/ref.png" "$tmp/ref.png" --json
python3 - "$tmp/out" <<'PY' || fail "--json of identical images"
import json, sys
d = json.load(open(sys.argv[1]))
assert sorted(d) == sorted(["mse", "rmse", "relmse", "psnr", "ssim", "flip", "nonfinite"]), d
assert d["nonfinite"] == 0, d
assert d["mse"] == 0 and d["flip"] == 0 and d["ssim"] == 1 and d["psnr"] is None, d
PY

# Different images: all numbers, FLIP in (0, 1), and --difftol decides the exit status.
expect 0 "$drift" diff "$tmp/ref.png" "$tmp/test.png" --json --ppd 40
python3 - "$tmp/out" <<'PY' || fail "--json of different images"
import json, sys
d = json.load(open(sys.argv[1]))
assert sorted(d) == sorted(["mse", "rmse", "relmse", "psnr", "ssim", "flip", "nonfinite"]), d
assert d.pop("nonfinite") == 0, d
assert all(isinstance(v, float) for v in d.values()), d
assert d["mse"] > 0 and 0 < d["flip"] < 1 and d["ssim"] < 1 and d["psnr"] > 0, d
assert abs(d["rmse"] ** 2 - d["mse"]) < 1e-12, d
PY
expect 1 "$drift" diff "$tmp/ref.png" "$tmp/test.png" --difftol 0
grep -q "exceeds" "$tmp/err" || fail "--difftol failure is explained"
expect 0 "$drift" diff "$tmp/ref.png" "$tmp/test.png" --difftol 1

# Heat map: a PNG of the same size appears.
expect 0 "$drift" diff "$tmp/ref.png" "$tmp/test.png" --heatmap "$tmp/heat.png"
[ -s "$tmp/heat.png" ] || fail "--heatmap writes the file"
# drift diff exits 1 on a size mismatch, so this fails unless the heat map is REF's size.
expect 0 "$drift" diff "$tmp/ref.png" "$tmp/heat.png"
expect 1 "$drift" diff "$tmp/ref.png" "$tmp/test.png" --heatmap "$tmp/no/such/dir/heat.png"
ls "$tmp/no" >/dev/null 2>&1 && fail "failed heat map leaves nothing behind"

# Errors: missing, corrupt, unsupported, size mismatch — exit 1 and the file is named.
expect 1 "$drift" diff "$tmp/missing.png" "$tmp/ref.png"
grep -q "missing.png" "$tmp/err" || fail "missing file is named"
expect 1 "$drift" diff "$tmp/ref.png" "$tmp/corrupt.png"
grep -q "corrupt.png" "$tmp/err" || fail "corrupt file is named"
expect 1 "$drift" diff "$tmp/garbage.exr" "$tmp/ref.png"
grep -q "garbage.exr" "$tmp/err" || fail "corrupt EXR is named"
expect 1 "$drift" diff "$tmp/ref.png" "$tmp/ref.bmp"
expect 1 "$drift" diff "$tmp/ref.png" "$tmp/small.png"
grep -q "sizes differ" "$tmp/err" || fail "size mismatch is explained"

# NaN and infinite pixels (issue 18): counted, reported, exit 1 unless --ignore-nonfinite,
# and then the metrics are over the finite pixels. EXRs written by hand (uncompressed).
PYTHONPATH="$(dirname "$0")" python3 - "$tmp" <<'PY'
import sys
from make_exr import exr
d = sys.argv[1]
exr(d + "/flat.exr", 8, 6, lambda x, y: (0.5, 0.5, 0.5))
exr(d + "/nan.exr", 8, 6, lambda x, y: (float("nan") if (x, y) == (3, 2) else 0.5, 0.5, 0.5))
exr(d + "/inf.exr", 8, 6, lambda x, y: (0.5, float("inf") if x == 0 else 0.5, 0.5))
PY
expect 1 "$drift" diff "$tmp/flat.exr" "$tmp/nan.exr"
grep -q "^nonfinite *1$" "$tmp/out" || fail "the NaN pixel is counted in plain output"
grep -q "1 of 48 pixels are NaN or infinite" "$tmp/err" || fail "the NaN pixel is reported"
grep -q "^mse *0$" "$tmp/out" || fail "mse is over the finite pixels, not nan"
expect 1 "$drift" diff "$tmp/inf.exr" "$tmp/flat.exr" --json
python3 - "$tmp/out" <<'PY' || fail "--json counts infinite pixels"
import json, sys
d = json.load(open(sys.argv[1]))
assert d["nonfinite"] == 6 and d["mse"] == 0, d
PY
expect 1 "$drift" diff "$tmp/nan.exr" "$tmp/inf.exr" --difftol 1
expect 0 "$drift" diff "$tmp/nan.exr" "$tmp/inf.exr" --ignore-nonfinite --json
python3 - "$tmp/out" <<'PY' || fail "--ignore-nonfinite: metrics over the finite pixels"
import json, math, sys
d = json.load(open(sys.argv[1]))
assert d["nonfinite"] == 7 and d["mse"] == 0 and d["psnr"] is None, d
assert all(v is None or math.isfinite(v) for v in d.values()), d
PY
grep -q "over the 41 finite pixels" "$tmp/err" || fail "--ignore-nonfinite says what was measured"

# A FIFO or a device is refused at once, as info and render do (it used to hang).
mkfifo "$tmp/fifo.png"
expect 1 timeout 10 "$drift" diff "$tmp/fifo.png" "$tmp/ref.png"
grep -q "fifo.png.*not a regular file" "$tmp/err" || fail "a FIFO reference is refused by name"
expect 1 timeout 10 "$drift" diff "$tmp/ref.png" "$tmp/fifo.png"
grep -q "fifo.png" "$tmp/err" || fail "a FIFO test image is refused by name"
ln -s /dev/zero "$tmp/zero.png"
expect 1 timeout 10 "$drift" diff "$tmp/ref.png" "$tmp/zero.png"
grep -q "not a regular file" "$tmp/err" || fail "a device is refused"

# A DWAB panorama as shipped and its ZIP re-encoding are the same image (the C++ shim decodes
# DWA); a truncated DWAB file is an error naming the file and the codec.
hdri="$DRIFT_SOURCE_DIR/../shared/scenes/hdri"
if [ -f "$hdri/dwab/studio.exr" ]; then
    expect 0 "$drift" diff "$hdri/dwab/studio.exr" "$hdri/studio.exr" --json
    python3 -c 'import json,sys; d=json.load(open(sys.argv[1])); assert d["mse"] == 0 and d["flip"] == 0, d' \
        "$tmp/out" || fail "DWAB and ZIP studio.exr differ"
    head -c 60000 "$hdri/dwab/studio.exr" >"$tmp/cut_dwab.exr"
    expect 1 "$drift" diff "$tmp/cut_dwab.exr" "$hdri/studio.exr"
    grep -q "cut_dwab.exr.*DWAB" "$tmp/err" || fail "truncated DWAB file is named with its codec"
else
    echo "cli.diff: skipped the DWAB checks: $hdri/dwab is absent"
fi

# A truncated .hdr is an error naming the file (stb_image decoded it without one, or looped).
python3 - "$tmp" <<'PY'
import sys
def hdr(path, w, h, rle, cut=0):
    out = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n" + ("-Y %d +X %d\n" % (h, w)).encode()
    for y in range(h):
        if rle:
            out += bytes([2, 2, w >> 8, w & 255]) + bytes([128 + w, 128] * 3 + [128 + w, 129])
        else:
            out += bytes([128, 128, 128, 129]) * w
    open(path, "wb").write(out[:len(out) - cut])
d = sys.argv[1]
hdr(d + "/flat.hdr", 4, 4, False)
hdr(d + "/flat_cut.hdr", 4, 4, False, 5)
hdr(d + "/rle.hdr", 16, 4, True)
hdr(d + "/rle_cut.hdr", 16, 4, True, 3)
PY
expect 0 timeout 20 "$drift" diff "$tmp/flat.hdr" "$tmp/flat.hdr"
expect 0 timeout 20 "$drift" diff "$tmp/rle.hdr" "$tmp/rle.hdr"
for cut in flat_cut rle_cut; do
    expect 1 timeout 20 "$drift" diff "$tmp/$cut.hdr" "$tmp/$cut.hdr"
    grep -q "$cut.hdr.*truncated" "$tmp/err" || fail "truncated $cut.hdr is named"
done

# --mask (per-object metrics, issue 41): a test image brighter than REF on its left 12 columns
# only; masks of the left 8 columns, of the right 8 and of nothing. The masked MSE and luminance
# ratio are checked against python's own sums over the same pixels.
PYTHONPATH="$(dirname "$0")" python3 - "$tmp" <<'PY'
import sys
from make_exr import exr
d = sys.argv[1]
ref = lambda x, y: (0.1 + 0.02 * x, 0.2 + 0.01 * y, 0.3)
exr(d + "/mref.exr", 32, 24, ref)
exr(d + "/mtest.exr", 32, 24, lambda x, y: tuple(c * (1.5 if x < 12 else 1.0) for c in ref(x, y)))
exr(d + "/mleft.exr", 32, 24, lambda x, y: (1.0 if x < 8 else 0.0,) * 3)
exr(d + "/mright.exr", 32, 24, lambda x, y: (0.7 if x >= 24 else 0.3,) * 3)
exr(d + "/mnone.exr", 32, 24, lambda x, y: (0.2, 0.2, 0.2))
exr(d + "/msmall.exr", 16, 24, lambda x, y: (1.0, 1.0, 1.0))
PY
expect 0 "$drift" diff "$tmp/mref.exr" "$tmp/mtest.exr" --json
cp "$tmp/out" "$tmp/whole.json"
expect 0 "$drift" diff "$tmp/mref.exr" "$tmp/mtest.exr" --json --mask "$tmp/mleft.exr"
cp "$tmp/out" "$tmp/left.json"
expect 0 "$drift" diff "$tmp/mref.exr" "$tmp/mtest.exr" --json --mask "$tmp/mright.exr"
cp "$tmp/out" "$tmp/right.json"
python3 - "$tmp" <<'PY' || fail "--mask: metrics over the masked pixels"
import json, sys
d = sys.argv[1]
w, l, r = (json.load(open(d + "/%s.json" % n)) for n in ("whole", "left", "right"))
assert sorted(l) == sorted(["mse", "rmse", "relmse", "psnr", "flip", "luminance", "nonfinite",
                            "mask_pixels"]), l
assert l["mask_pixels"] == 8 * 24 and r["mask_pixels"] == 8 * 24, (l, r)
ref = lambda x, y: (0.1 + 0.02 * x, 0.2 + 0.01 * y, 0.3)
px = [ref(x, y) for y in range(24) for x in range(8)]
mse = sum((0.5 * c) ** 2 for p in px for c in p) / (3 * len(px))
assert abs(l["mse"] - mse) < 1e-6 * mse, (l["mse"], mse)
assert abs(l["luminance"] - 1.5) < 1e-5, l
assert r["mse"] == 0 and r["luminance"] == 1 and r["psnr"] is None, r
assert l["flip"] > w["flip"] > r["flip"] >= 0, (l["flip"], w["flip"], r["flip"])
PY
expect 1 "$drift" diff "$tmp/mref.exr" "$tmp/mtest.exr" --mask "$tmp/mleft.exr" --difftol 0.01
grep -q "exceeds" "$tmp/err" || fail "--difftol applies to the masked FLIP"
expect 1 "$drift" diff "$tmp/mref.exr" "$tmp/mtest.exr" --mask "$tmp/mnone.exr"
grep -q "selects no pixel" "$tmp/err" || fail "an empty mask is explained"
expect 1 "$drift" diff "$tmp/mref.exr" "$tmp/mtest.exr" --mask "$tmp/msmall.exr"
grep -q "msmall.exr.*16x24" "$tmp/err" || fail "a mask of another size is named"
expect 1 "$drift" diff "$tmp/mref.exr" "$tmp/mtest.exr" --mask "$tmp/missing_mask.exr"
grep -q "missing_mask.exr" "$tmp/err" || fail "a missing mask is named"
expect 2 "$drift" diff "$tmp/mref.exr" "$tmp/mtest.exr" --mask "$tmp/mleft.exr" --frames 0:1

if [ "$failures" -ne 0 ]; then
    echo "$failures failure(s)" >&2
    exit 1
fi
echo "cli.diff: all checks passed"
