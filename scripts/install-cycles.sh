#!/usr/bin/env bash
# Install Blender (Cycles) from the Debian archive, for the Cycles comparison bench
# (bench/cycles/). Idempotent: does nothing if `blender --version` already works.
# Debian 12 ships Blender 3.4.1. Nothing is downloaded from outside the Debian archive.
set -euo pipefail

if command -v blender >/dev/null 2>&1 && blender --version >/dev/null 2>&1 &&
    dpkg-query -W -f='${Status}' python3-numpy 2>/dev/null | grep -q "install ok installed"; then
    echo "install-cycles: $(blender --version 2>/dev/null | head -n1) already installed"
    exit 0
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then
    if command -v sudo >/dev/null 2>&1; then SUDO="sudo"; else
        echo "install-cycles: need root (or sudo) to apt-get install blender" >&2; exit 1
    fi
fi

export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update
# --no-install-recommends keeps it smaller; blender still pulls in python3 + OpenEXR/OIIO libs.
# python3-numpy: Blender's glTF importer needs it (bench/cycles/gltf_cycles.py).
$SUDO apt-get install -y --no-install-recommends blender python3-numpy

blender --version | head -n1
