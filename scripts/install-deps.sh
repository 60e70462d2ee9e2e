#!/usr/bin/env bash
# Installs the Debian 12 packages drift needs to build, test (python3 for the CLI tests), check
# formatting and fuzz (SDL2 for `drift view`; Xvfb and xauth for its window test under
# xvfb-run; chromium for the `drift report` page test; Open MPI for `mpirun -n N drift render`;
# Blender for the Cycles comparison of a Blender-exported glTF).
# Idempotent: when everything is present it does nothing (no apt-get update), so repeated runs
# are fast.
set -euo pipefail

packages=(
  build-essential cmake pkg-config clang libclang-rt-14-dev
  libembree-dev libassimp-dev libcjson-dev libopenexr-dev libstb-dev zlib1g-dev libkissfft-dev libexpat1-dev
  libopencolorio-dev
  libcmocka-dev valgrind clang-format git python3
  libsdl2-dev xvfb xauth
  chromium
  libopenmpi-dev openmpi-bin
  # Blender 3.4 (Cycles, its glTF exporter and importer; numpy for the importer): the
  # cli.blender_gltf test (issue 22). ~70 MB download, ~600 MB installed.
  blender python3-numpy
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
[ ${#missing[@]} -eq 0 ] && exit 0

sudo_cmd=()
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "install-deps: run as root or install sudo" >&2; exit 1; }
  sudo_cmd=(sudo)
fi
echo "install-deps: installing ${missing[*]}"
"${sudo_cmd[@]}" apt-get update -qq
DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
