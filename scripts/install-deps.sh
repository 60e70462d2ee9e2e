#!/usr/bin/env bash
# Installs the Debian 12 packages drift needs, in three sets:
#   (no argument)  building and running drift: compilers, CMake and the libraries
#                  (scripts/run-default.sh; ~150 packages, ~520 MB on a bare Debian 12)
#   --viewer       also SDL2 for the `drift view` window (~170 packages more: X11, Wayland, audio)
#   --test         also the viewer's SDL2 and the test tools (scripts/test.sh; ~2.5 GB in all):
#                  clang and its runtime (fuzzers),
#                  cmocka, valgrind, clang-format, Python with numpy, Xvfb and xauth for the
#                  viewer's window test, Chromium for the `drift report` page test, Open MPI for
#                  `mpirun -n N drift render`, Blender for the Cycles comparison of a
#                  Blender-exported glTF (~600 MB of the test set)
# Idempotent: when everything is present it installs nothing (no apt-get update). It prints
# what it installed and the disk space that took.
set -euo pipefail
export LC_ALL=C

build_packages=(
  build-essential cmake pkg-config
  libembree-dev libassimp-dev libcjson-dev libopenexr-dev libstb-dev zlib1g-dev libkissfft-dev libexpat1-dev
  libopencolorio-dev
)
viewer_packages=(libsdl2-dev)
test_packages=(
  clang libclang-rt-14-dev libcmocka-dev valgrind clang-format git python3 python3-numpy
  xvfb xauth
  chromium
  libopenmpi-dev openmpi-bin
  # Blender 3.4 (Cycles, its glTF exporter and importer; numpy for the importer): the
  # cli.blender_gltf test (issue 22). ~70 MB download, ~600 MB installed.
  blender
)
packages=("${build_packages[@]}")
set_name="build"
case "${1:-}" in
  --viewer) packages+=("${viewer_packages[@]}"); set_name="build and viewer" ;;
  --test) packages+=("${viewer_packages[@]}" "${test_packages[@]}"); set_name="build and test" ;;
  "") ;;
  *) echo "usage: install-deps.sh [--viewer | --test]" >&2; exit 2 ;;
esac

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: the $set_name set (${#packages[@]} packages) is installed; nothing to do"
  exit 0
fi

sudo_cmd=()
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "install-deps: run as root or install sudo" >&2; exit 1; }
  sudo_cmd=(sudo)
fi
installed() { dpkg-query -W -f='${Status} ${Package} ${Installed-Size}\n' | grep '^install ok installed'; }
before=$(installed | awk '{ print $4 }' | sort)
echo "install-deps: installing ${missing[*]}"
"${sudo_cmd[@]}" apt-get update -qq
DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
# What came in (the named packages and their dependencies) and its size.
installed | awk '{ print $4, $5 }' | sort >"${TMPDIR:-/tmp}/install-deps.$$"
new=$(join -v1 "${TMPDIR:-/tmp}/install-deps.$$" <(echo "$before"))
rm -f "${TMPDIR:-/tmp}/install-deps.$$"
count=$(echo "$new" | grep -c . || true)
kb=$(echo "$new" | awk '{ s += $2 } END { print s + 0 }')
echo "install-deps: the $set_name set: $count packages installed, $((kb / 1024)) MB on disk"
echo "$new" | awk '{ printf "  %-40s %8.1f MB\n", $1, $2 / 1024 }' | sort -k2 -rn | head -15
[ "$count" -gt 15 ] && echo "  ... and $((count - 15)) more"
exit 0
