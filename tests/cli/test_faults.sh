#!/usr/bin/env bash
# Issue 43: nothing hangs, nothing aborts, nothing is clobbered (docs/reliability.md).
# A full disk (a real write failure under `ulimit -f 0`, and ENOSPC injected with
# DRIFT_TEST_DISK_FULL) in render (reference and hybrid), glare and report; FIFOs and
# /dev/zero as every kind of input; coordinates past DRIFT_SCENE_COORD_MAX; the PLY face of no
# indices and the header of 65 properties; outputs naming a scene's .mtl or glTF .bin and a
# report folder holding files drift did not write; NaN texels in an environment map; the stage
# file a killed run leaves. Each case must end within seconds (`timeout`: status 124 is a
# hang), with a status below 128 (no abort) and its message. $1 is the drift binary.
set -u
drift="$1"
here="$(dirname "$0")"
source "$here/common.sh"
root=${DRIFT_SOURCE_DIR:-$(cd "$here/../.." && pwd)}
small=(--width 16 --height 16 --spp 1 --quiet)

# run STATUS SECONDS CMD...: like expect, but a run past SECONDS is a hang, a status of 128
# or more a crash, and a sanitizer report a failure.
run() {
    local want="$1" limit="$2" before=$failures
    shift 2
    timeout -k 2 "$limit" "$@" >"$tmp/out" 2>"$tmp/err"
    local got=$?
    if [ "$got" -eq 124 ] || [ "$got" -eq 137 ]; then
        fail "hung (killed after $limit s): $*"
    elif [ "$got" -ge 128 ]; then
        fail "crashed (status $got): $*"
    elif [ "$want" = "nonzero" ] && [ "$got" -eq 0 ]; then
        fail "expected a failure, got exit 0: $*"
    elif [ "$want" != "nonzero" ] && [ "$got" -ne "$want" ]; then
        fail "expected exit $want, got $got: $*"
    fi
    if grep -qE "AddressSanitizer|LeakSanitizer|runtime error" "$tmp/err"; then
        fail "sanitizer report: $*"
    fi
    [ "$failures" -eq "$before" ] || sed 's/^/  stderr: /' "$tmp/err" >&2
}
says() { grep -qF -- "$1" "$tmp/err" || fail "$2: stderr does not say '$1'"; }
only() { # only DIR FILE...: DIR holds exactly these names
    local dir="$1"
    shift
    local want have
    want=$( (($# > 0)) && printf '%s\n' "$@" | sort | tr '\n' ' ')
    have=$(ls -A "$dir" | sort | tr '\n' ' ')
    [ "$have" = "$want" ] || fail "$dir holds '$have', expected '$want'"
}

# --- A full disk: an error within seconds, "disk full", nothing half-written ------------

# A real write failure (the kernel's EFBIG) on the EXR header: the EXR writer deadlocked.
mkdir "$tmp/full"
(
    trap '' XFSZ
    ulimit -f 0
    exec timeout -k 2 20 "$drift" render "${small[@]}" --out "$tmp/full/a.exr"
) >/dev/null 2>"$tmp/full.err"
status=$?
[ "$status" -eq 1 ] || fail "ulimit -f 0: exit $status, expected 1 (124: the EXR writer hung)"
only "$tmp/full"

# ENOSPC injected into every image write: reference, hybrid, glare, report.
run 1 20 env DRIFT_TEST_DISK_FULL=0 "$drift" render "${small[@]}" --out "$tmp/full/a.exr"
says "disk full" "render, disk full"
run 1 20 env DRIFT_TEST_DISK_FULL=0 "$drift" render "${small[@]}" --mode hybrid \
    --indirect none --out "$tmp/full/h.exr" --stats "$tmp/full/h.json"
says "disk full" "hybrid render, disk full"
only "$tmp/full" a.ckpt # the reference render's work, kept
run 0 20 "$drift" render "${small[@]}" --out "$tmp/in.exr"
run 1 20 env DRIFT_TEST_DISK_FULL=0 "$drift" glare "$tmp/in.exr" --out "$tmp/full/g.exr" \
    --psf-size 32 --threads 1
says "disk full" "glare, disk full"
only "$tmp/full" a.ckpt
run nonzero 60 env DRIFT_TEST_DISK_FULL=0 "$drift" report --out "$tmp/full/r" --size 16 \
    --ref-spp 1 --sweep-spp 1 --threads 2 --effects shadows
says "disk full" "report, disk full"

# The render is kept: the failed final write leaves FILE.ckpt; the same command then writes
# the bytes of an uninterrupted render.
mkdir "$tmp/keep"
run 1 20 env DRIFT_TEST_DISK_FULL=3000 "$drift" render "${small[@]}" --spp 4 --out "$tmp/keep/a.exr"
says "disk full" "render, disk full mid-file"
says "the render is kept in $tmp/keep/a.ckpt" "render, disk full mid-file"
only "$tmp/keep" a.ckpt
run 0 20 "$drift" render "${small[@]}" --spp 4 --out "$tmp/keep/a.exr"
run 0 20 "$drift" render "${small[@]}" --spp 4 --out "$tmp/keep/b.exr"
cmp -s "$tmp/keep/a.exr" "$tmp/keep/b.exr" || fail "the resumed render differs from a fresh one"
only "$tmp/keep" a.exr a.png b.exr b.png

# --- The stage file of a killed run is removed by the next ----------------------------
mkdir "$tmp/stage"
dead=$(sh -c 'echo $$') # a process that has ended
touch "$tmp/stage/a.png.stage-$dead" "$tmp/stage/a.exr.stage-$dead.tmp-0badf00d" \
    "$tmp/stage/a.png.stage-$$"
run 0 20 "$drift" render "${small[@]}" --out "$tmp/stage/a.exr"
only "$tmp/stage" a.exr a.png "a.png.stage-$$" # a live run's stage is not touched

# --- Special files: refused at once as "not a regular file" ----------------------------
mkdir "$tmp/sp"
cp "$root"/scenes/cornell-box/cornell_box.{json,obj,mtl} "$tmp/sp/"
for f in fifo.json fifo.obj fifo.ckpt fifo.mtl fifo.bin fifo.edit.json fifo.lambda.json; do
    mkfifo "$tmp/sp/$f"
done
sed 's/^mtllib .*/mtllib fifo.mtl/' "$tmp/sp/cornell_box.obj" >"$tmp/sp/fifo_mtl.obj"
python3 - "$tmp/sp" <<'PY'
import json, struct, sys
d = sys.argv[1]
pos = struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0)
idx = struct.pack("<3H", 0, 1, 2) + b"\0\0"
open(d + "/tri.bin", "wb").write(pos + idx)
def gltf(uri):
    return json.dumps({
        "asset": {"version": "2.0"}, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
        "buffers": [{"uri": uri, "byteLength": 44}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36},
                        {"buffer": 0, "byteOffset": 36, "byteLength": 6}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                       "min": [0, 0, 0], "max": [1, 1, 0]},
                      {"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"}]})
open(d + "/tri.gltf", "w").write(gltf("tri.bin"))
open(d + "/fifo_bin.gltf", "w").write(gltf("fifo.bin"))
PY
sp="$tmp/sp"
notreg() { # notreg LABEL CMD...: refused within seconds, non-zero, "not a regular file"
    local label="$1"
    shift
    run nonzero 20 "$@"
    says "not a regular file" "$label"
}
notreg "FIFO scene" "$drift" render "$sp/fifo.json" "${small[@]}" --out "$sp/a.exr"
notreg "FIFO OBJ scene" "$drift" render "$sp/fifo.obj" "${small[@]}" --out "$sp/a.exr"
notreg "FIFO mtllib" "$drift" render "$sp/fifo_mtl.obj" "${small[@]}" --out "$sp/a.exr"
says "fifo.mtl" "FIFO mtllib"
notreg "FIFO glTF buffer" "$drift" info "$sp/fifo_bin.gltf"
says "fifo.bin" "FIFO glTF buffer"
notreg "FIFO --resume" "$drift" render "${small[@]}" --out "$sp/a.exr" --resume "$sp/fifo.ckpt"
notreg "/dev/zero --resume" "$drift" render "${small[@]}" --out "$sp/a.exr" --resume /dev/zero
notreg "FIFO --reflection-edits" "$drift" render "${small[@]}" --out "$sp/a.exr" \
    --reflection-edits "$sp/fifo.edit.json"
notreg "/dev/zero --reflection-edits" "$drift" render "${small[@]}" --out "$sp/a.exr" \
    --reflection-edits /dev/zero
notreg "FIFO --lambda" "$drift" render "${small[@]}" --out "$sp/a.exr" --mode hybrid \
    --indirect none --refine sir --lambda "$sp/fifo.lambda.json"
mkdir "$sp/r"
mkfifo "$sp/r/manifest.json"
notreg "FIFO report manifest" "$drift" report --out "$sp/r" --size 16 --effects shadows

# --- Outputs never overwrite an input, a scene's side files included --------------------
cp "$sp/cornell_box.mtl" "$sp/mtl.orig"
run 2 20 "$drift" render "$sp/cornell_box.obj" "${small[@]}" --out "$sp/a.exr" \
    --stats "$sp/cornell_box.mtl"
says "refusing to overwrite" "--stats at the scene's .mtl"
cmp -s "$sp/cornell_box.mtl" "$sp/mtl.orig" || fail "--stats overwrote the scene's .mtl"
cp "$sp/tri.bin" "$sp/bin.orig"
run 2 20 "$drift" render "$sp/tri.gltf" "${small[@]}" --out "$sp/a.exr" --stats "$sp/tri.bin"
cmp -s "$sp/tri.bin" "$sp/bin.orig" || fail "--stats overwrote the glTF's .bin"
for name in manifest.json index.html; do
    mkdir "$sp/foreign-$name"
    echo '{"mine": true}' >"$sp/foreign-$name/$name"
    run 2 20 "$drift" report --out "$sp/foreign-$name" --size 16 --effects shadows
    says "did not write" "report --out holding a foreign $name"
    [ "$(cat "$sp/foreign-$name/$name")" = '{"mine": true}' ] || fail "report overwrote $name"
    only "$sp/foreign-$name" "$name"
done

# --- Absurd numbers: an error naming the file (and line), never an abort in Embree --------
mkdir "$tmp/far"
sed 's/"position": \[278, 273, -800\]/"position": [278, 2e19, -800]/' \
    "$root/scenes/cornell-box/cornell_box.json" >"$tmp/far/camera.json"
cp "$root"/scenes/cornell-box/cornell_box.{obj,mtl} "$tmp/far/"
run 1 20 "$drift" render "$tmp/far/camera.json" "${small[@]}" --out "$tmp/far/a.exr"
says "camera.json:5:" "camera at 2e19"
{ cat "$root/scenes/cornell-box/cornell_box.obj"; printf 'v 1e19 0 0\nv 0 1 0\nv 0 0 1\nf -3 -2 -1\n'; } \
    >"$tmp/far/vertex.obj"
cp "$root/scenes/cornell-box/cornell_box.mtl" "$tmp/far/"
run 1 20 "$drift" render "$tmp/far/vertex.obj" "${small[@]}" --out "$tmp/far/a.exr"
says "outside the +-1e+12" "vertex at 1e19"
run 2 20 "$drift" render "${small[@]}" --mode hybrid --indirect none --reflections envmap \
    --probe 2e19,0,0 --out "$tmp/far/a.exr"
says "--probe" "--probe at 2e19"
edit_scene="$root/scenes/edit-teapot/edit_teapot.json"
printf '{\n "constraints": [\n  { "mesh": "defaultobject", "point": [0, 1.4, 2.0],\n    "view": [0, 2e19, 7.5], "target": [0, 9, 0] }\n ]\n}\n' \
    >"$tmp/far/view.edit.json"
run 2 20 "$drift" render "$edit_scene" "${small[@]}" --reflection-edits "$tmp/far/view.edit.json" \
    --out "$tmp/far/a.exr"
says "view.edit.json:4:" "edit-file view at 2e19"
only "$tmp/far" camera.json cornell_box.obj cornell_box.mtl vertex.obj view.edit.json

# --- PLY: a face of no indices (assimp aborted), 65 properties and no end_header (hung) -----
mkdir "$tmp/ply"
printf 'ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n0\n' \
    >"$tmp/ply/empty_face.ply"
run 1 20 "$drift" info "$tmp/ply/empty_face.ply"
says "empty_face.ply:14:" "PLY face of no indices"
{
    printf 'ply\nformat ascii 1.0\nelement vertex 3\n'
    for i in $(seq 0 70); do printf 'property float p%d\n' "$i"; done
} >"$tmp/ply/many.ply"
run 1 20 "$drift" info "$tmp/ply/many.ply"
says "more than 64 properties" "PLY header of 71 properties"

# --- NaN and infinite texels: replaced at load, counted, no NaN pixel ---------------------
mkdir "$tmp/nan"
PYTHONPATH="$here" python3 - "$tmp/nan" "$root/scenes/cornell-box/cornell_box.json" <<'PY'
import json, sys
from make_exr import exr
d = sys.argv[1]
# Every texel NaN or infinite but one: an unguarded map makes every sky pixel NaN.
exr(d + "/sky.exr", 8, 4, lambda x, y: (0.5 if (x, y) == (0, 0) else
                                        float("nan") if x % 2 else float("inf"), 0.5, 0.5))
s = json.load(open(sys.argv[2]))
s["environment"] = {"map": "sky.exr"}
s["camera"]["target"] = [278, 273, -1600]  # looking away from the box, at the sky
for m in s["meshes"]:
    m["path"] = sys.argv[2].rsplit("/", 1)[0] + "/" + m["path"]
json.dump(s, open(d + "/sky.json", "w"))
PY
run 0 30 "$drift" render "$tmp/nan/sky.json" "${small[@]}" --mode hybrid --indirect none \
    --out "$tmp/nan/h.exr"
says "NaN or infinite; set to 0" "NaN texels"
run 0 20 "$drift" diff "$tmp/nan/h.exr" "$tmp/nan/h.exr"
grep -q "^nonfinite 0" "$tmp/out" || fail "the hybrid frame of a NaN sky holds NaN pixels"

if [ "$failures" -ne 0 ]; then
    echo "$failures failure(s)" >&2
    exit 1
fi
echo "faults: all passed"
