#!/usr/bin/env bash
# README command 2: build (if needed) and run the whole test suite with ctest.
# With --sanitize, uses the separate build with ASan + UBSan that the fuzzers share
# (scripts/build_sanitize.sh; CAMPROJ_SANITIZE_FLAGS, CMakeLists.txt).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
if [[ "${1:-}" == "--sanitize" ]]; then
  build="$root/build/sanitize"
  bash "$root/scripts/build_sanitize.sh"
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
