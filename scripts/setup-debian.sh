#!/usr/bin/env bash
# Installs the Debian 12 packages TopoSpline builds and runs with (only the missing ones).
# Needs root (apt-get). Fails loudly.
set -euo pipefail

packages=(
  build-essential cmake ninja-build
  paraview paraview-dev python3-paraview libcgal-dev libeigen3-dev libglpk-dev libgmp-dev libmpfr-dev
  xvfb xauth
  qtbase5-dev qttools5-dev libqt5svg5-dev libqt5x11extras5-dev libqt5opengl5-dev qtxmlpatterns5-dev-tools
  libutfcpp-dev libboost-dev libexpat1-dev
  libavcodec-dev libavformat-dev libavutil-dev libswscale-dev libfreetype-dev
  libgdal-dev libgl2ps-dev libglew-dev libhdf5-openmpi-dev libjpeg-dev liblz4-dev
  liblzma-dev libxml2-dev libopenmpi-dev libnetcdf-dev libgl-dev libpng-dev
  python3-dev libtheora-dev libtiff-dev libx11-dev zlib1g-dev
  libdouble-conversion-dev python3-mpi4py python3-numpy python3-matplotlib
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#packages[@]} Debian packages present"
  exit 0
fi
if [ "$(id -u)" -ne 0 ]; then
  echo "setup: missing packages: ${missing[*]}" >&2
  echo "setup: run as root (or with sudo) so that apt-get can install them" >&2
  exit 1
fi
echo "setup: installing ${#missing[@]} Debian packages: ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
apt-get update -qq
apt-get install -y --no-install-recommends "${missing[@]}"
