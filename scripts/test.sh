#!/usr/bin/env bash
# README command 2: build (if needed) and run the whole test suite with ctest.
# With --sanitize, uses a separate build with ASan + UBSan (CAMPROJ_SANITIZE_FLAGS, CMakeLists.txt).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
if [[ "${1:-}" == "--sanitize" ]]; then
  build="$root/build/sanitize"
  # -O1 -g1: line tables for readable reports at a fraction of -O2 -g's compile time.
  bash "$root/scripts/build.sh" "$build" -DCAMPROJ_SANITIZE=ON -DCMAKE_BUILD_TYPE=Debug \
    "-DCMAKE_CXX_FLAGS_DEBUG=-O1 -g1"
  # The 2000-scene stress test costs ~330 s of CPU under the sanitizers; its first 400 scenes
  # (50 per category) give them every path to watch, and the Release run checks all 2000.
  export CAMPROJ_STRESS_SCENES=${CAMPROJ_STRESS_SCENES:-400}
else
  build="$root/build/release"
  bash "$root/scripts/build.sh" "$build"
fi
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=0}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
ctest --test-dir "$build" --output-on-failure -j "$(nproc)"
