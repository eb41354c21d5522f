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
bash "$root/scripts/build_release.sh" "$build" bench_clicks.sh camproj_bench

bench="${build#"$root"/}/apps/bench"
echo "\$ $bench --clicks --out docs/bench/clicks $*"
"$bench" --clicks --out docs/bench/clicks "$@"
