#!/usr/bin/env bash
# CLI tests for `drift glare`: help, a still and a sequence on small HDR inputs, determinism
# for a seed, the PSF and aperture outputs, and bad input (not HDR, missing, corrupt, bad
# options) exiting 2 with nothing written. $1 is the drift binary.
set -u
drift="$1"
source "$(dirname "$0")/common.sh"

# A 40x30 Radiance .hdr (flat RGBE scanlines) with a bright point, and non-HDR inputs.
python3 - "$tmp" <<'PY'
import sys
d = sys.argv[1]
w, h = 40, 30
def rgbe(r, g, b):
    import math
    v = max(r, g, b)
    if v < 1e-32:
        return bytes(4)
    m, e = math.frexp(v)
    s = m * 256.0 / v
    return bytes([int(r * s), int(g * s), int(b * s), e + 128])
px = b""
for y in range(h):
    for x in range(w):
        px += rgbe(500.0, 450.0, 400.0) if (x, y) == (20, 15) else rgbe(0.05, 0.05, 0.06)
head = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y %d +X %d\n" % (h, w)
open(d + "/in.hdr", "wb").write(head + px)
open(d + "/in.png", "wb").write(b"\x89PNG\r\n\x1a\n")
open(d + "/corrupt.exr", "wb").write(b"v/1\x01" + b"\x00" * 40)
PY
# Uncompressed scanline EXRs written by hand: one with a NaN pixel, one valid.
PYTHONPATH="$(dirname "$0")" python3 - "$tmp" <<'PY'
import sys
from make_exr import exr
d = sys.argv[1]
exr(d + "/nan.exr", 8, 6, lambda x, y: (float("nan") if (x, y) == (3, 2) else 0.5, 0.5, 0.5))
exr(d + "/ok.exr", 8, 6, lambda x, y: (0.5, 2.0 if (x, y) == (3, 2) else 0.1, 0.5))
PY
small=(--psf-size 32 --threads 1)

# Help and usage errors.
expect 0 "$drift" glare --help
grep -q "usage: drift glare" "$tmp/out" || fail "--help prints usage on stdout"
grep -q -- "--out-pattern" "$tmp/out" || fail "--help lists --out-pattern from the option table"
expect 2 "$drift" glare
expect 2 "$drift" glare "$tmp/in.hdr"
expect 2 "$drift" glare "$tmp/in.hdr" --out "$tmp/x.exr" --bogus
expect 2 "$drift" glare "$tmp/in.hdr" --out "$tmp/x.exr" --seed nope
expect 2 "$drift" glare "$tmp/in.hdr" --out "$tmp/x.exr" --mode sideways
expect 2 "$drift" glare "$tmp/in.hdr" --out "$tmp/x.exr" --psf-size 100
grep -q "power of two" "$tmp/err" || fail "--psf-size 100 says it is not a power of two"
expect 2 "$drift" glare "$tmp/in.hdr" --out "$tmp/x.tiff"
grep -q -- "--out expects .*x.tiff'" "$tmp/err" || fail "a bad --out names the option and value"
expect 2 "$drift" glare "$tmp/in.hdr" --out ""
grep -q -- "--out expects a file name" "$tmp/err" || fail "an empty --out is refused by name"
expect 2 "$drift" glare "$tmp/in.hdr" --out "$tmp/x.exr" --fps 0
grep -q -- "--fps expects .*got '0'" "$tmp/err" || fail "--fps 0 names the option and value"
expect 2 "$drift" glare "$tmp/in.hdr" --frames 3 --out "$tmp/x.exr"
expect 2 "$drift" glare "$tmp/in.hdr" --frames 3 --out-pattern "$tmp/f_%d_%d.exr"
expect 2 "$drift" glare "$tmp/in.hdr" --out "$tmp/x.exr" --psf "$tmp/psf.tif"
expect 2 "$drift" glare "$tmp/in.hdr" --out "$tmp/x.exr" --aperture "$tmp/ap.png"
grep -q -- "--aperture expects an .exr name" "$tmp/err" || fail "a bad --aperture is named"
expect 2 "$drift" glare "$tmp/in.hdr" "$tmp/in2.hdr" --out "$tmp/x.exr"

# Bad input files: clear errors naming the file, exit 2, nothing written.
expect 2 "$drift" glare "$tmp/in.png" --out "$tmp/x.exr"
grep -q "in.png' is not an HDR image" "$tmp/err" || fail "a PNG input is refused as not HDR"
expect 2 "$drift" glare "$tmp/missing.exr" --out "$tmp/x.exr"
grep -q "missing.exr" "$tmp/err" || fail "a missing input is named"
expect 2 "$drift" glare "$tmp/corrupt.exr" --out "$tmp/x.exr" --psf "$tmp/xpsf.exr"
grep -q "corrupt.exr" "$tmp/err" || fail "a corrupt input is named"
[ -e "$tmp/x.exr" ] && fail "a refused run wrote its output"
[ -e "$tmp/xpsf.exr" ] && fail "a refused run wrote its PSF"
expect 2 "$drift" glare "$tmp/nan.exr" --out "$tmp/x.exr" --psf "$tmp/xpsf.exr" "${small[@]}"
grep -q "nan.exr' has NaN or infinite pixels" "$tmp/err" || fail "a NaN input is refused by name"
grep -q "pixel (3, 2)" "$tmp/err" || fail "the first NaN pixel is named"
[ -e "$tmp/x.exr" ] && fail "a NaN input wrote its output"
[ -e "$tmp/xpsf.exr" ] && fail "a NaN input wrote its PSF"
expect 0 "$drift" glare "$tmp/ok.exr" --out "$tmp/ok_out.exr" "${small[@]}"
[ -s "$tmp/ok_out.exr" ] || fail "an EXR input is read and glared"
# An unwritable output fails without leaving a partial file.
expect 1 "$drift" glare "$tmp/in.hdr" --out "$tmp/no/such/dir/x.exr" "${small[@]}"
grep -q "no/such/dir/x.exr" "$tmp/err" || fail "an unwritable output is named"
expect 1 "$drift" glare "$tmp/in.hdr" --out "$tmp/y.exr" --psf "$tmp/no/psf.exr" "${small[@]}"
[ -e "$tmp/y.exr" ] && fail "an unwritable PSF path let the output be written"
ls "$tmp" | grep -q "tmp-" && fail "a temporary file was left behind"

# A still: output, PSF and aperture, and the same bytes for the same seed.
expect 0 "$drift" glare "$tmp/in.hdr" --out "$tmp/a.exr" --psf "$tmp/psf.exr" \
    --aperture "$tmp/ap.exr" --seed 3 "${small[@]}"
grep -q "pupil" "$tmp/out" || fail "a still prints the pupil"
for f in a.exr psf.exr ap.exr; do [ -s "$tmp/$f" ] || fail "$f written"; done
expect 0 "$drift" glare "$tmp/in.hdr" --out "$tmp/b.exr" --seed 3 "${small[@]}"
cmp -s "$tmp/a.exr" "$tmp/b.exr" || fail "same seed, same bytes"
# PNG output, reading a.exr back as the input. (Its second ZIP chunk, rows 16-29, compresses
# to exactly its raw size, 6720 bytes: drift_image_save_exr must store it raw, or rows 16-29
# read back as garbage, NaNs among them, and this run is refused.)
expect 0 "$drift" glare "$tmp/a.exr" --out "$tmp/a.png" "${small[@]}" --diffraction fraunhofer
[ -s "$tmp/a.png" ] || fail "PNG output written"

# The billboard path.
expect 0 "$drift" glare "$tmp/in.hdr" --out "$tmp/bb.exr" --method billboard "${small[@]}"
[ -s "$tmp/bb.exr" ] || fail "billboard output written"
expect 2 "$drift" glare "$tmp/in.hdr" --out "$tmp/bb.exr" --method sprites

# A dynamic sequence, with per-frame PSFs.
expect 0 "$drift" glare "$tmp/in.hdr" --frames 3 --fps 5 --out-pattern "$tmp/f_%02d.exr" \
    --psf "$tmp/p_%02d.exr" --seed 5 "${small[@]}"
for i in 00 01 02; do
    [ -s "$tmp/f_$i.exr" ] || fail "frame $i written"
    [ -s "$tmp/p_$i.exr" ] || fail "PSF $i written"
done
grep -q "3 frames" "$tmp/out" || fail "a sequence prints its ms a frame"
cmp -s "$tmp/p_00.exr" "$tmp/p_02.exr" && fail "the dynamic eye changes the PSF between frames"
# An input pattern reads one image a frame.
expect 0 "$drift" glare "$tmp/f_%02d.exr" --frames 2 --out-pattern "$tmp/g_%d.exr" "${small[@]}"
[ -s "$tmp/g_1.exr" ] || fail "an input pattern makes frame 1"
# A bad frame in an input sequence stops the run before anything is written.
cp "$tmp/ok.exr" "$tmp/s_0.exr"
cp "$tmp/nan.exr" "$tmp/s_1.exr"
expect 2 "$drift" glare "$tmp/s_%d.exr" --frames 2 --out-pattern "$tmp/t_%d.exr" "${small[@]}"
grep -q "s_1.exr' has NaN" "$tmp/err" || fail "the NaN frame of a sequence is named"
[ -e "$tmp/t_0.exr" ] && fail "a sequence with a bad frame wrote its first frame"

# --glare is the last pass of drift render in either mode.
expect 0 "$drift" render --spp 2 --width 48 --height 48 --threads 2 --quiet --out "$tmp/pt.exr"
expect 0 "$drift" render --spp 2 --width 48 --height 48 --threads 2 --quiet --glare static \
    --out "$tmp/pt_glare.exr"
cmp -s "$tmp/pt.exr" "$tmp/pt_glare.exr" && fail "render --glare static changes the path tracer's image"
expect 0 "$drift" render --mode hybrid --width 48 --height 48 --threads 2 --quiet --glare dynamic \
    --ism-vpls 8 --out "$tmp/hy_glare.exr"
[ -s "$tmp/hy_glare.exr" ] || fail "render --mode hybrid --glare dynamic writes its image"
expect 2 "$drift" render --glare sideways --out "$tmp/bad.exr"
grep -q "\-\-glare expects one of none, static, dynamic, got .sideways." "$tmp/err" || fail "a bad --glare is named"
expect 2 "$drift" render --glare static --shadows pcss --out "$tmp/bad.exr"
grep -q "shadows needs --mode hybrid" "$tmp/err" || fail "other hybrid options still need hybrid mode"
[ -e "$tmp/bad.exr" ] && fail "a refused render wrote its image"

[ "$failures" -eq 0 ] || { echo "$failures failure(s)" >&2; exit 1; }
echo "cli glare: ok"
