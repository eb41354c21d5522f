#!/usr/bin/env bash
# The click benchmark of the default fitting path (apps/bench/clicks.cc): builds apps/bench in
# Release and runs `bench --clicks --out docs/bench/clicks`, which writes clicks.md and clicks.csv
# there. Extra arguments go to the bench, e.g. scripts/bench_clicks.sh --quick --out /tmp/clicks
# (a later --out wins). Single-threaded; a few minutes.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build="$root/build/release"
cd "$root"

# Release build of the bench alone (scripts/build.sh's configuration).
if [[ ! -f "$build/build.ninja" ]]; then
  cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
fi
build_type=$(sed -n 's/^CMAKE_BUILD_TYPE:STRING=//p' "$build/CMakeCache.txt")
if [[ "$build_type" != "Release" ]]; then
  echo "bench_clicks.sh: $build is configured as '$build_type', not Release; times would mislead" >&2
  exit 1
fi
cmake --build "$build" --target camproj_bench

bench="${build#"$root"/}/apps/bench"
echo "\$ $bench --clicks --out docs/bench/clicks $*"
"$bench" --clicks --out docs/bench/clicks "$@"
