#!/usr/bin/env bash
# Configures and builds TopoSpline in build/ (Release). Usage: scripts/build.sh
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${TOPOSPLINE_BUILD_DIR:-$here/build}"
mkdir -p "$build"
cmake -S "$here" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release > "$build/configure.log" 2>&1 || {
  cat "$build/configure.log" >&2; echo "build: cmake configure failed" >&2; exit 1; }
cmake --build "$build" -j "$(nproc)"
echo "build: plugin at $build/lib/paraview-plugins/TopoSpline/TopoSpline.so"
