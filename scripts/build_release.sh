#!/usr/bin/env bash
# Configures BUILD_DIR once as scripts/build.sh does and builds TARGET, refusing a build directory
# configured other than Release (times measured there would mislead). For the measuring scripts
# (bench.sh, bench_clicks.sh, bench_stage_cost.sh, stability.sh), which name themselves as CALLER
# in the message. Usage: scripts/build_release.sh BUILD_DIR CALLER TARGET
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=$1
caller=$2
target=$3
if [[ ! -f "$build/build.ninja" ]]; then
  cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DCAMPROJ_PYTHON=ON >/dev/null
elif ! grep -q "^CAMPROJ_PYTHON:" "$build/CMakeCache.txt"; then
  cmake "$build" -DCAMPROJ_PYTHON=ON >/dev/null
fi
build_type=$(sed -n 's/^CMAKE_BUILD_TYPE:STRING=//p' "$build/CMakeCache.txt")
if [[ "$build_type" != "Release" ]]; then
  echo "$caller: $build is configured as '$build_type', not Release; times would mislead" >&2
  exit 1
fi
cmake --build "$build" --target "$target"
