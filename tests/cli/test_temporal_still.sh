#!/usr/bin/env bash
# A still camera converges under temporal reuse (docs/temporal.md): a cheap hybrid frame of the
# Cornell box at 32 x 32 (hard shadows, ISM indirect light from 64 VPLs, reseeded every frame),
# frames 0..15 of a camera path that does not move, with --temporal on, scored by FLIP against
# the path tracer at 128 spp. The error is monotone in the frames within noise (each of frames
# 2, 4, 8, 16 at most 2% above the one before, and frame 16 below 0.95 x frame 1), and
# `--frames N --temporal on` (the viewer's set-up, drift/temporal.h) writes frame N - 1 of that
# sequence bit for bit, for 1 and 2 threads.
# Still refinement --still-refine on adds a path-traced sample a frame: frame 16
# goes below 0.8 x what the hybrid alone (--still-refine off) has converged to after 16 frames,
# the hybrid's bias (measured: refined 0.212, 0.198, 0.168, 0.137, 0.117; the hybrid alone
# 0.212, 0.198, 0.193, 0.189, 0.185). $1 is the drift binary.
set -u
drift="$1"
source "$(dirname "$0")/common.sh"
scene="$DRIFT_SOURCE_DIR/scenes/cornell-box/cornell_box.json"
cat >"$tmp/still.json" <<'JSON'
{"fps": 24, "keyframes": [
  {"time": 0.0, "position": [278, 273, -800], "target": [278, 273, 0]}
]}
JSON
size=(--width 32 --height 32 --threads 2 --quiet)
hybrid=(--mode hybrid --temporal on --indirect ism --ism-vpls 64 --reflections none --shadows hard)
expect 0 "$drift" render "$scene" "${size[@]}" --spp 128 --out "$tmp/ref.exr"
mkdir -p "$tmp/s"
expect 0 "$drift" render "$scene" "${size[@]}" "${hybrid[@]}" --still-refine on \
    --camera-path "$tmp/still.json" --animation 0:15 --out "$tmp/s/f_%04d.exr"
expect 0 "$drift" render "$scene" "${size[@]}" "${hybrid[@]}" --still-refine on --frames 16 \
    --out "$tmp/last.exr"
expect 0 "$drift" render "$scene" "${size[@]}" "${hybrid[@]}" --still-refine on --frames 16 \
    --threads 1 --out "$tmp/last1.exr"
expect 0 "$drift" render "$scene" "${size[@]}" "${hybrid[@]}" --frames 16 --still-refine off \
    --out "$tmp/hybrid_only.exr"
"$drift" diff "$tmp/last.exr" "$tmp/last1.exr" >"$tmp/threads.txt" 2>&1 ||
    fail "--frames 16 differs between 1 and 2 threads: $(cat "$tmp/threads.txt")"
grep -Eq '^flip +0(\.0+)?$' "$tmp/threads.txt" ||
    fail "--frames 16 differs between 1 and 2 threads: $(grep flip "$tmp/threads.txt")"
# --frames' last image is the sequence's frame 15 when the path's camera is the scene camera's
# (the same seeds and sub-pixel offsets).
"$drift" diff "$tmp/s/f_0015.exr" "$tmp/last.exr" >"$tmp/same.txt" 2>&1 ||
    fail "--frames 16 --temporal on differs from frame 15: $(cat "$tmp/same.txt")"
grep -Eq '^flip +0(\.0+)?$' "$tmp/same.txt" ||
    fail "--frames 16 --temporal on is not frame 15: $(grep flip "$tmp/same.txt")"
flips=()
for k in 0000 0001 0003 0007 0015; do
    f=$("$drift" diff "$tmp/ref.exr" "$tmp/s/f_$k.exr" | awk '$1 == "flip" { print $2 }')
    flips+=("$f")
done
hybrid_only=$("$drift" diff "$tmp/ref.exr" "$tmp/hybrid_only.exr" | awk '$1 == "flip" { print $2 }')
echo "FLIP against the path tracer after 1, 2, 4, 8, 16 frames: ${flips[*]}"
echo "the hybrid alone after 16 frames: $hybrid_only"
python3 - "$hybrid_only" "${flips[@]}" <<'PY' ||
import sys
h = float(sys.argv[1])
f = [float(x) for x in sys.argv[2:]]
assert all(b <= 1.02 * a for a, b in zip(f, f[1:])), f
assert f[-1] < 0.95 * f[0], f
assert f[-1] < 0.8 * h, (f, h)
PY
    fail "a still camera does not converge below the hybrid's ${hybrid_only}: ${flips[*]}"
# --still-refine progressive: after the first still frame no hybrid frame is rendered (the
# stats' "hybrid": false) and each frame path-traces 4 samples a pixel, the hybrid fading out by
# sample count. Monotone within 2% over 1, 2, 4, 8, 16 frames, frame 16 below 0.8 x the
# refinement that keeps rendering hybrid frames (--still-refine on, above), and bit-identical
# for 1 and 2 threads (measured: 0.213, 0.162, 0.129, 0.102, 0.082). It is the default: the
# 1-thread run names no --still-refine.
mkdir -p "$tmp/p"
expect 0 "$drift" render "$scene" "${size[@]}" "${hybrid[@]}" --still-refine progressive \
    --camera-path "$tmp/still.json" --animation 0:15 --out "$tmp/p/f_%04d.exr" \
    --stats "$tmp/p/stats.json"
expect 0 "$drift" render "$scene" "${size[@]}" "${hybrid[@]}" \
    --frames 16 --threads 1 --out "$tmp/p/last1.exr"
"$drift" diff "$tmp/p/f_0015.exr" "$tmp/p/last1.exr" >"$tmp/p/threads.txt" 2>&1 ||
    fail "progressive: 1 and 2 threads differ: $(cat "$tmp/p/threads.txt")"
grep -Eq '^flip +0(\.0+)?$' "$tmp/p/threads.txt" ||
    fail "progressive: 1 and 2 threads differ: $(grep flip "$tmp/p/threads.txt")"
pflips=()
for k in 0000 0001 0003 0007 0015; do
    f=$("$drift" diff "$tmp/ref.exr" "$tmp/p/f_$k.exr" | awk '$1 == "flip" { print $2 }')
    pflips+=("$f")
done
echo "progressive: FLIP after 1, 2, 4, 8, 16 frames: ${pflips[*]}"
python3 - "$tmp/p/stats.json" "${flips[4]}" "${pflips[@]}" <<'PY' ||
import json, sys
frames = json.load(open(sys.argv[1]))["frames"]
assert "hybrid" not in frames[0] and all(f["hybrid"] is False for f in frames[1:]), frames
on = float(sys.argv[2])
f = [float(x) for x in sys.argv[3:]]
assert all(b <= 1.02 * a for a, b in zip(f, f[1:])), f
assert f[-1] < 0.8 * on, (f, on)
PY
    fail "progressive does not converge below --still-refine on's ${flips[4]}: ${pflips[*]}"
# The moving refinement is for sequences: without --animation (or --temporal on) a usage error;
# with them three frames render (its quality is unit.temporal's test_moving_refine_*).
expect 2 "$drift" render "$scene" "${size[@]}" "${hybrid[@]}" --moving-refine path \
    --out "$tmp/mr.exr"
mkdir -p "$tmp/mr"
expect 0 "$drift" render "$scene" "${size[@]}" "${hybrid[@]}" --moving-refine residual \
    --camera-path "$tmp/still.json" --animation 0:2 --out "$tmp/mr/f_%04d.exr"
exit $((failures > 0))
