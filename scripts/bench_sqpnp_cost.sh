#!/usr/bin/env bash
# Instructions per SQPnP pose, ours (lib/src/fit/sqpnp.h) against OpenCV's
# cv::solvePnP(SOLVEPNP_SQPNP), on the stage-cost bench's scenes (apps/bench/sqpnp_cost.cc):
# for each N, `sqpnp_cost` under callgrind with --solver ours, opencv and none; per call =
# (solver - none) / scenes. Instruction counts do not depend on the machine's load.
#
#   scripts/bench_sqpnp_cost.sh [BUILD_DIR] [--n N,N,...] [--scenes S] [--plane]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build="$root/build/release"
counts="6,20,100"
scenes=40
plane=""
while [[ $# -gt 0 ]]; do
  case "$1" in
    --n) counts=$2; shift 2 ;;
    --scenes) scenes=$2; shift 2 ;;
    --plane) plane="--plane"; shift ;;
    -*) echo "bench_sqpnp_cost.sh: unknown argument $1" >&2; exit 1 ;;
    *) build=$1; shift ;;
  esac
done
command -v valgrind >/dev/null || { echo "bench_sqpnp_cost.sh: needs valgrind" >&2; exit 1; }
cmake --build "$build" --target camproj_sqpnp_cost >/dev/null
binary="$build/apps/sqpnp_cost"
instructions() {
  valgrind --tool=callgrind --callgrind-out-file=/dev/null "$binary" "$@" 2>&1 |
    sed -n 's/.*Collected : \([0-9]*\).*/\1/p'
}
printf '%6s %14s %14s %8s\n' N ours opencv ratio
for n in ${counts//,/ }; do
  none=$(instructions --solver none --n "$n" --scenes "$scenes" $plane)
  ours=$(( ($(instructions --solver ours --n "$n" --scenes "$scenes" $plane) - none) / scenes ))
  opencv=$(( ($(instructions --solver opencv --n "$n" --scenes "$scenes" $plane) - none) / scenes ))
  printf '%6d %14d %14d %8s\n' "$n" "$ours" "$opencv" \
         "$(awk -v a="$opencv" -v b="$ours" 'BEGIN { printf "%.1fx", a / b }')"
done
