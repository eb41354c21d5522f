#!/usr/bin/env bash
# README command 1: install the dependencies, build, and run the main job on bundled data: fit the
# projection-mapping example (a 1920x1080 projector, principal point at the bottom edge, 20 points
# on a box) and export its OpenGL matrices.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
bash "$root/scripts/install-deps.sh"
bash "$root/scripts/build.sh" "$root/build/release"
cd "$root"
camproj=./build/release/apps/camproj
echo
echo "$ camproj fit data/projector/points.csv --image-size 1920x1080 -o build/projector.json"
$camproj fit data/projector/points.csv --image-size 1920x1080 -o build/projector.json
echo
echo "$ camproj export build/projector.json --to gl"
$camproj export build/projector.json --to gl
