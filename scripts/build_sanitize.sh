#!/usr/bin/env bash
# Configures (once) and builds the sanitizer build, build/sanitize: clang, Debug at -O1 -g1,
# CAMPROJ_SANITIZE (ASan + UBSan, CAMPROJ_SANITIZE_FLAGS in CMakeLists.txt) and CAMPROJ_FUZZ
# (every object also carries libFuzzer's coverage, -fsanitize=fuzzer-no-link). One build serves
# both `scripts/test.sh --sanitize` (the test suite) and scripts/fuzz.sh (the libFuzzer targets),
# so CI compiles the instrumented library once.
# Usage: scripts/build_sanitize.sh [TARGET...]   (no target: everything)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build="$root/build/sanitize"
for tool in clang clang++ cmake ninja; do
  if ! command -v "$tool" >/dev/null; then
    echo "build_sanitize: $tool not found; run scripts/install-deps.sh" >&2
    exit 1
  fi
done
# A cache made with another compiler (this build was GCC's before) cannot be switched to clang
# in place: start it over.
if [[ -f "$build/CMakeCache.txt" ]] && ! grep -q '^CMAKE_CXX_COMPILER:.*clang' "$build/CMakeCache.txt"; then
  rm -rf "$build/CMakeCache.txt" "$build/CMakeFiles" "$build/build.ninja"
fi
if [[ ! -f "$build/build.ninja" ]]; then
  # -O1 -g1: line tables for readable reports at a fraction of -O2 -g's compile time.
  CC=clang CXX=clang++ cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Debug \
    "-DCMAKE_CXX_FLAGS_DEBUG=-O1 -g1" -DCAMPROJ_SANITIZE=ON -DCAMPROJ_FUZZ=ON >/dev/null
fi
targets=()
(($# > 0)) && targets=(--target "$@")
cmake --build "$build" "${targets[@]}"
