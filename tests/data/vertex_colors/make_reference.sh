#!/usr/bin/env bash
# Rebuilds tests/data/vertex_colors: painted.glb (make_painted.py) and Cycles 3.4's render of
# it through Blender's glTF importer (bench/cycles/gltf_cycles.py, 128x72, 1024 spp). Under a
# minute.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
src="$(cd "$here/../../.." && pwd)"
blender -b --factory-startup -noaudio --python "$here/make_painted.py" -- "$here"
blender -b --factory-startup -noaudio --python "$src/bench/cycles/gltf_cycles.py" -- \
    --gltf "$here/painted.glb" --spp 1024 --width 128 --height 72 --threads 2 \
    --out "$here/cycles_128x72.exr"
