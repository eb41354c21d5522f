#!/usr/bin/env bash
# Installs camproj's build and test dependencies from Debian 12's packages (nothing else is
# downloaded). Run as root (or with sudo available).
set -euo pipefail
packages=(
  build-essential cmake ninja-build pkg-config
  libceres-dev libopencv-dev libeigen3-dev
  libgtest-dev libgmock-dev libbenchmark-dev libcli11-dev nlohmann-json3-dev libglm-dev
  libegl-dev libgl-dev libopengl-dev libegl-mesa0 libgl1-mesa-dri
  clang libclang-rt-dev llvm  # scripts/fuzz.sh: clang, libFuzzer runtime, llvm-symbolizer
  python3-matplotlib  # scripts/plot_bench.py: the benchmark's plots (docs/bench/)
  pybind11-dev python3-pybind11 python3-numpy  # python/: the camproj Python module
  python3-pytest python3-opencv  # python/tests: the module's tests (cross-check with cv2)
  python3-distributed  # python/examples/dask_fit.py: scale-out on Dask
  help2man  # the man page installed with the CLI (apps/CMakeLists.txt)
)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]} == 0)); then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi
sudo=""
if [[ $(id -u) -ne 0 ]]; then sudo="sudo"; fi
echo "install-deps: installing ${missing[*]}"
$sudo env DEBIAN_FRONTEND=noninteractive apt-get update -qq
$sudo env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "install-deps: done"
