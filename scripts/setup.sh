#!/usr/bin/env bash
# README command 1: install the dependencies, build, and run the main job on bundled data.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
bash "$root/scripts/install-deps.sh"
bash "$root/scripts/build.sh" "$root/build/release"
cd "$root"
echo
echo "$ camproj export data/projector/camera.json --to gl"
./build/release/apps/camproj export data/projector/camera.json --to gl
