#!/usr/bin/env bash
# README command 1: installs what is missing, builds, and runs the pipeline on the built-in
# default field (or on the file given), writing VTK files, PNG pictures and summary.json.
# Usage: scripts/run-main.sh [--input FILE.vti] [--output DIR] ... (see --help)
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bash "$here/scripts/setup-debian.sh"
bash "$here/scripts/build.sh"
build="${TOPOSPLINE_BUILD_DIR:-$here/build}"
export TOPOSPLINE_PLUGIN="$build/lib/paraview-plugins/TopoSpline/TopoSpline.so"
# Rendering needs an X server: pvbatch runs under a virtual one (the display search starts at a
# random number: two "xvfb-run -a" starting together can otherwise pick the same display).
exec xvfb-run -a -n $((200 + RANDOM % 30000)) -s "-screen 0 1280x1024x24" pvbatch "$here/scripts/topospline_main.py" "$@"
