#!/usr/bin/env bash
# README command 2: installs what is missing, builds, and runs every test through CTest.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bash "$here/scripts/setup-debian.sh"
bash "$here/scripts/build.sh"
build="${TOPOSPLINE_BUILD_DIR:-$here/build}"
cd "$build"
ctest --output-on-failure -j 2 "$@"
