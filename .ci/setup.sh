#!/usr/bin/env bash
# Installs the Debian 12 packages Furrow builds against, only those missing. Fast when all are present.
set -euo pipefail
pkgs=(build-essential cmake pkg-config ccache git
      libeigen3-dev libtbb-dev nlohmann-json3-dev libopenvdb-dev libboost-iostreams-dev libblosc-dev
      libvtk9-dev libosmesa6-dev libimgui-dev libglfw3-dev
      libgtest-dev libgmock-dev libbenchmark-dev ffmpeg valgrind xvfb libxtst6 openmpi-bin libopenmpi-dev
      python3-dev pybind11-dev python3-pybind11 python3-numpy python3-pytest python3-matplotlib)
missing=()
for p in "${pkgs[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi
echo "furrow setup: installing ${missing[*]}"
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
