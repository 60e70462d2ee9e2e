#!/usr/bin/env bash
# Rebuilds tests/data/texture_transform: the glTF (make_texture_transform.py) and Cycles 3.4's
# render of it through Blender's glTF importer (bench/cycles/gltf_cycles.py, 32x32, 256 spp,
# direct light only: the quad only emits). Under a minute.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
src="$(cd "$here/../../.." && pwd)"
python3 "$here/make_texture_transform.py"
blender -b --factory-startup -noaudio --python "$src/bench/cycles/gltf_cycles.py" -- \
    --gltf "$here/tt.gltf" --spp 256 --width 32 --height 32 --threads 2 --max-bounces 0 \
    --out "$here/cycles_32x32.exr"
