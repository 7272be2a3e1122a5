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
# The virtual X server sometimes fails to come up under load ("bad X server connection"):
# up to two more tries, a few seconds apart, in that case only.
log=$(mktemp)
trap 'rm -f "$log"' EXIT
for attempt in 1 2 3; do
  [ "$attempt" -gt 1 ] && sleep 5
  set +e
  xvfb-run -a -n $((200 + RANDOM % 30000)) -s "-screen 0 1280x1024x24" \
    pvbatch "$here/scripts/topospline_main.py" "$@" 2>&1 | tee "$log"
  status=${PIPESTATUS[0]}
  set -e
  if [ "$status" -eq 0 ] || ! grep -q "bad X server connection" "$log"; then
    exit "$status"
  fi
  echo "main: the virtual X server failed to start; trying again" >&2
done
exit "$status"
