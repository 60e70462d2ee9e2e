#!/usr/bin/env bash
# Rebuilds tests/data/coverage: the small images and cards.gltf of the unit test
# (make_coverage.py), and for tests/cli/test_coverage_cycles.sh the Blender scene
# (make_blender_cards.py: cards_blender.glb) and Cycles 3.4's render of it through Blender's
# glTF importer (bench/cycles/gltf_cycles.py, 128x72, 1024 spp). About a minute.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
src="$(cd "$here/../../.." && pwd)"
(cd "$here" && python3 make_coverage.py)
blender -b --factory-startup -noaudio --python "$here/make_blender_cards.py" -- "$here"
blender -b --factory-startup -noaudio --python "$src/bench/cycles/gltf_cycles.py" -- \
    --gltf "$here/cards_blender.glb" --spp 1024 --width 128 --height 72 --threads 2 \
    --out "$here/cycles_128x72.exr"
