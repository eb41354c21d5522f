#!/usr/bin/env bash
# Configures (once) and builds camproj. Usage: scripts/build.sh [BUILD_DIR] [extra cmake args...]
# Turns on the Python module (CAMPROJ_PYTHON; off by itself in a sanitizer build), also in a
# build directory configured before the option existed.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-"$root/build/release"}
shift || true
if [[ ! -f "$build/build.ninja" ]]; then
  cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DCAMPROJ_PYTHON=ON "$@" >/dev/null
elif ! grep -q '^CAMPROJ_PYTHON:' "$build/CMakeCache.txt"; then
  cmake "$build" -DCAMPROJ_PYTHON=ON >/dev/null
fi
cmake --build "$build"
