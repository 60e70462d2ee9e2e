#!/usr/bin/env bash
# Rebuilds the cached inputs of tests/cli/test_ggx_cycles.sh: Blender writes the scene
# (export_ggx_scene.py) and Cycles 3.4 renders it (bench/cycles/gltf_cycles.py: no denoising,
# no adaptive sampling, box filter, Standard view, Multiscatter GGX) at 64x48, 1024 spp (SPP overrides);
# the same for the textured scene without spheres (--textured --no-spheres) in textured/; and the
# rough sphere's coverage mask (bench/cycles/gltf_object_masks.py). A few minutes.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
src="$(cd "$here/../../.." && pwd)"
blend() { blender -b --factory-startup -noaudio --python "$@"; }
blend "$here/export_ggx_scene.py" -- --out "$here"
blend "$src/bench/cycles/gltf_cycles.py" -- --gltf "$here/ggx_scene.glb" --spp "${SPP:-1024}" --multiscatter \
    --width 64 --height 48 --threads 2 --out "$here/cycles_64x48.exr"
# The rough (0.8) sphere's coverage mask, for the test's per-object check (drift diff --mask).
blend "$src/bench/cycles/gltf_object_masks.py" -- --gltf "$here/ggx_scene.glb" --width 64 --height 48 \
    --out "$here/masks"
mv "$here/masks/mask_Metal3.exr" "$here/mask_metal3.exr" && rm -r "$here/masks"
blend "$here/export_ggx_scene.py" -- --out "$here/textured" --textured --no-spheres
blend "$src/bench/cycles/gltf_cycles.py" -- --gltf "$here/textured/ggx_scene.gltf" --spp "${SPP:-1024}" \
    --multiscatter --width 64 --height 48 --threads 2 --out "$here/textured/cycles_64x48.exr"
