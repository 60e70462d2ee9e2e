#!/usr/bin/env bash
# Installs what building and running drift needs (scripts/install-deps.sh: no test tools, no
# viewer), builds drift (Release) and renders the built-in Cornell box with the reference path
# tracer. Extra arguments go to `drift render` (e.g. --spp 256). For `drift view`:
# bash scripts/install-deps.sh --viewer, then run this again.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
cmake -S . -B build/release -DCMAKE_BUILD_TYPE=Release -DDRIFT_BUILD_TESTS=OFF >/dev/null
cmake --build build/release -j"$(nproc)" >/dev/null
mkdir -p out
./build/release/bin/drift render --spp 64 --out out/cornell-box.exr "$@"
