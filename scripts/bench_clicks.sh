#!/usr/bin/env bash
# The click benchmark of the default fitting path (apps/bench/clicks.cc): builds apps/bench in
# Release and runs `bench --clicks --out docs/bench/clicks` (scenes 0-99 of every band: the
# development set the default path's rules were chosen on), then the held-out scenes 100-299
# into docs/bench/clicks/held-out; each writes clicks.md and clicks.csv. Extra arguments go to
# both runs, e.g. scripts/bench_clicks.sh --quick --out /tmp/clicks (a later --out wins).
# Single-threaded; about 3 minutes.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build="$root/build/release"
cd "$root"

# Release build of the bench alone (scripts/build.sh's configuration).
bash "$root/scripts/build_release.sh" "$build" bench_clicks.sh camproj_bench

bench="${build#"$root"/}/apps/bench"
echo "\$ $bench --clicks --out docs/bench/clicks $*"
"$bench" --clicks --out docs/bench/clicks "$@"
echo "\$ $bench --clicks --first-scene 100 --scenes 200 --out docs/bench/clicks/held-out $*"
"$bench" --clicks --first-scene 100 --scenes 200 --out docs/bench/clicks/held-out "$@"
