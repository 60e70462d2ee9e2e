#!/usr/bin/env bash
# CLI tests for sequences (docs/temporal.md): `drift render --animation A:B --camera-path F.json`
# writes one numbered EXR and PNG a frame and per-frame stats, in both modes and with temporal
# reuse, the same bits for 1 and 2 threads; usage errors exit 2 and write nothing; a bad camera
# path is named with its file and line. $1 is the drift binary.
set -u
drift="$1"
source "$(dirname "$0")/common.sh"
scene="$DRIFT_SOURCE_DIR/scenes/cornell-box/cornell_box.json"
cat >"$tmp/path.json" <<'JSON'
{"fps": 24, "keyframes": [
  {"time": 0.0, "position": [278, 273, -800], "target": [278, 273, 0]},
  {"time": 0.1, "position": [240, 290, -760], "target": [290, 260, 0], "fov_y": 42},
  {"time": 0.2, "position": [300, 260, -700], "target": [260, 270, 0], "fov_y": 40}
]}
JSON
small=(--width 24 --height 24 --quiet --camera-path "$tmp/path.json")
hybrid=(--mode hybrid --indirect none --light-samples 1 --temporal on)

for threads in 1 2; do
    mkdir -p "$tmp/h$threads" "$tmp/r$threads"
    expect 0 "$drift" render "$scene" "${small[@]}" "${hybrid[@]}" --threads "$threads" \
        --animation 2:5 --out "$tmp/h$threads/f_%04d.exr" --stats "$tmp/h$threads/s.json"
    expect 0 "$drift" render "$scene" "${small[@]}" --spp 2 --threads "$threads" \
        --animation 0:1 --out "$tmp/r$threads/f_%02d.exr"
done
for k in 0002 0003 0004 0005; do
    [ -s "$tmp/h1/f_$k.exr" ] && [ -s "$tmp/h1/f_$k.png" ] || fail "hybrid frame $k not written"
    cmp -s "$tmp/h1/f_$k.exr" "$tmp/h2/f_$k.exr" || fail "hybrid frame $k differs across threads"
done
[ -e "$tmp/h1/f_0001.exr" ] || [ -e "$tmp/h1/f_0006.exr" ] && fail "frames outside 2:5 written"
for k in 00 01; do
    cmp -s "$tmp/r1/f_$k.exr" "$tmp/r2/f_$k.exr" || fail "reference frame $k differs across threads"
done
cmp -s "$tmp/h1/f_0002.exr" "$tmp/h1/f_0005.exr" && fail "the camera path did not move the camera"
# Dynamic glare stepped by the sequence's 1 / fps: the same bits for 1 and 2 threads.
for threads in 1 2; do
    mkdir -p "$tmp/g$threads"
    expect 0 "$drift" render "$scene" "${small[@]}" --mode hybrid --indirect none --glare dynamic \
        --threads "$threads" --animation 0:2 --out "$tmp/g$threads/f_%d.exr"
done
cmp -s "$tmp/g1/f_2.exr" "$tmp/g2/f_2.exr" || fail "a glare sequence differs across threads"
python3 - "$tmp/h1/s.json" <<'PY' || fail "sequence stats incomplete"
import json, sys
s = json.load(open(sys.argv[1]))
assert s["temporal"] is True and s["fps"] == 24 and s["first_frame"] == 2, s
f = s["frames"]
assert [e["frame"] for e in f] == [2, 3, 4, 5], f
assert all(e["ms"] > 0 and e["frame_ms"] > 0 and e["rays"] > 0 for e in f), f
assert abs(f[1]["time"] - 3 / 24) < 1e-6, f
PY

# drift diff --frames: a sequence against itself has no error; against the hybrid frames it
# has FLIP and temporal error per frame, in JSON, and the SVG plot.
expect 0 "$drift" diff "$tmp/r1/f_%02d.exr" "$tmp/r2/f_%02d.exr" --frames 0:1 --json
python3 -c 'import json,sys; d=json.load(open(sys.argv[1])); assert d["mean_flip"]==0 and d["mean_temporal_error"]==0, d' \
    "$tmp/out" || fail "a sequence against itself has an error"
mkdir -p "$tmp/hn"
expect 0 "$drift" render "$scene" "${small[@]}" --mode hybrid --indirect none --threads 2 \
    --animation 0:1 --out "$tmp/hn/f_%d.exr"
expect 0 "$drift" diff "$tmp/r1/f_%02d.exr" "$tmp/hn/f_%d.exr" --frames 0:1 --json \
    --plot "$tmp/plot.svg"
python3 - "$tmp/out" <<'PY' || fail "diff --frames JSON incomplete"
import json, sys
d = json.load(open(sys.argv[1]))
f = d["frames"]
assert [e["frame"] for e in f] == [0, 1] and f[0]["temporal_error"] is None, d
assert all(0 < e["flip"] < 1 for e in f) and f[1]["temporal_error"] > 0, d
assert abs(d["mean_flip"] - (f[0]["flip"] + f[1]["flip"]) / 2) < 1e-9, d
PY
grep -q "<polyline" "$tmp/plot.svg" || fail "--plot wrote no plot"
expect 2 "$drift" diff "$tmp/r1/f_%02d.exr" "$tmp/hn/f_%d.exr" --plot "$tmp/p2.svg"
expect 2 "$drift" diff "$tmp/r1/f_00.exr" "$tmp/hn/f_0.exr" --frames 0:1
[ -e "$tmp/p2.svg" ] && fail "a usage error wrote the plot"

# Usage errors: exit 2, nothing written.
mkdir -p "$tmp/bad"
expect 2 "$drift" render "$scene" "${small[@]}" --animation 0:1 --out "$tmp/bad/x.exr"
grep -q "%04d" "$tmp/err" || fail "--out without a frame number not explained"
expect 2 "$drift" render "$scene" --camera-path "$tmp/path.json" --out "$tmp/bad/x.exr"
grep -q -- "--camera-path needs --animation" "$tmp/err" || fail "--camera-path alone accepted"
expect 2 "$drift" render "$scene" "${small[@]}" --animation 5:2 --out "$tmp/bad/f_%d.exr"
expect 2 "$drift" render "$scene" "${small[@]}" --temporal on --animation 0:1 \
    --out "$tmp/bad/f_%d.exr"
grep -q -- "needs --mode hybrid" "$tmp/err" || fail "--temporal in reference mode accepted"
printf '{"keyframes": [\n {"time": 0, "position": [0, 0, 1], "target": [0, 0, 0]},\n {"time": "x"}]}\n' \
    >"$tmp/bad.json"
expect 2 "$drift" render "$scene" --width 8 --height 8 --camera-path "$tmp/bad.json" \
    --animation 0:1 --out "$tmp/bad/f_%d.exr"
grep -q "bad.json:3" "$tmp/err" || fail "a bad camera path not named with its line: $(cat "$tmp/err")"
[ -z "$(ls "$tmp/bad")" ] || fail "a usage error wrote $(ls "$tmp/bad")"

exit $((failures > 0))
