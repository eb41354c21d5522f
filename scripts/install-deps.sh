#!/usr/bin/env bash
# Installs camproj's build and test dependencies: Debian 12's packages, then the npm packages
# pinned in web/package-lock.json (three.js, which `camproj view` inlines into its pages) with
# `npm ci` into web/node_modules. Nothing else is downloaded. Run as root (or with sudo available).
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
  chromium  # tests/view_browser_test.sh: the camproj view page rendered in headless Chromium
)
# npm ci of web/package-lock.json: Debian's nodejs and npm, unless an npm is already there (a
# NodeSource nodejs bundles its own npm and conflicts with Debian's npm package).
command -v npm >/dev/null || packages+=(nodejs npm)
root=$(cd "$(dirname "$0")/.." && pwd)
# three.js at the version and hash web/package-lock.json pins; the build embeds it (lib/CMakeLists.txt).
install_web() {
  if [[ -f "$root/web/node_modules/three/package.json" ]] &&
     cmp -s "$root/web/package-lock.json" "$root/web/node_modules/.package-lock.json.camproj"; then
    echo "install-deps: web/node_modules up to date"
    return
  fi
  (cd "$root/web" && npm ci --ignore-scripts --no-audit --no-fund --loglevel=error)
  cp "$root/web/package-lock.json" "$root/web/node_modules/.package-lock.json.camproj"
  echo "install-deps: web/node_modules installed (npm ci)"
}
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]} == 0)); then
  echo "install-deps: all ${#packages[@]} packages present"
  install_web
  exit 0
fi
sudo=""
if [[ $(id -u) -ne 0 ]]; then sudo="sudo"; fi
echo "install-deps: installing ${missing[*]}"
$sudo env DEBIAN_FRONTEND=noninteractive apt-get update -qq
$sudo env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "install-deps: done"
install_web
