#!/usr/bin/env bash
# Rebuilds the cached inputs of tests/cli/test_clearcoat_cycles.sh: Blender writes the scene
# (export_clearcoat_scene.py, KHR_materials_clearcoat) and Cycles 3.4 renders it
# (bench/cycles/gltf_cycles.py: no denoising, no adaptive sampling, box filter, Standard view,
# Multiscatter GGX) at 64x48, 1024 spp (SPP overrides). A few minutes.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
src="$(cd "$here/../../.." && pwd)"
blend() { nice blender -b --factory-startup -noaudio --python "$@"; }
blend "$here/export_clearcoat_scene.py" -- --out "$here"
blend "$src/bench/cycles/gltf_cycles.py" -- --gltf "$here/clearcoat_scene.glb" --spp "${SPP:-1024}" \
    --multiscatter --width 64 --height 48 --threads 2 --out "$here/cycles_64x48.exr"
