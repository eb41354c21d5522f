#!/usr/bin/env bash
# What the default path costs on clean scenes, in instructions (docs/bench/stage_cost.md): builds
# apps/bench in Release, runs `bench --stage-cost --n N` under callgrind for every N (instruction
# counts do not depend on the machine's load) and once natively (wall time), the same with
# --one-fit (one fit of OpenCV's model on the same scenes), and writes the table with
# scripts/stage_cost.py: per N the instructions per fit of the baseline (recorded in
# stage_cost.py), of this tree, per stage, and of one fit. Single-threaded; about 6 minutes.
#
#   scripts/bench_stage_cost.sh [--out FILE] [--n N,N,...]   (default docs/bench/stage_cost.md)
#   scripts/bench_stage_cost.sh --baseline REV
#       instructions per fit of REV's FitCameraAuto on the same scenes (the constants in
#       stage_cost.py): builds REV's library in a temporary git worktree and this tree's
#       apps/bench/stage_cost.cc against it (it uses only public API older than the default path).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
out="$root/docs/bench/stage_cost.md"
counts="6,8,12,20,100,1000"
baseline=""
while [[ $# -gt 0 ]]; do
  case "$1" in
    --out) out=$2; shift 2 ;;
    --n) counts=$2; shift 2 ;;
    --baseline) baseline=$2; shift 2 ;;
    *) echo "bench_stage_cost.sh: unknown argument $1" >&2; exit 1 ;;
  esac
done
command -v valgrind >/dev/null || { echo "bench_stage_cost.sh: needs valgrind" >&2; exit 1; }
work=$(mktemp -d)
cleanup() {
  if [[ -n "$baseline" && -d "$work/tree" ]]; then
    git -C "$root" worktree remove --force "$work/tree"
  fi
  rm -rf "$work"
}
trap cleanup EXIT

if [[ -n "$baseline" ]]; then
  git -C "$root" worktree add --detach "$work/tree" "$baseline" >/dev/null
  cp "$root/apps/bench/stage_cost.h" "$root/apps/bench/stage_cost.cc" \
     "$root/apps/bench/point_counts.h" "$work/tree/apps/bench/"
  cat >>"$work/tree/apps/CMakeLists.txt" <<'CMAKE'
add_executable(stage_cost_baseline bench/stage_cost.cc)
target_compile_definitions(stage_cost_baseline PRIVATE CAMPROJ_STAGE_COST_MAIN)
target_link_libraries(stage_cost_baseline PRIVATE camproj)
CMAKE
  cmake -S "$work/tree" -B "$work/build" -G Ninja -DCMAKE_BUILD_TYPE=Release \
    -DCAMPROJ_BUILD_TESTS=OFF >/dev/null
  cmake --build "$work/build" --target stage_cost_baseline
  bench=("$work/build/apps/stage_cost_baseline")
else
  build="$root/build/release"
  bash "$root/scripts/build_release.sh" "$build" bench_stage_cost.sh camproj_bench
  bench=("$build/apps/bench" --stage-cost)
fi

"${bench[@]}" --n "$counts" >"$work/wall.csv"
for n in ${counts//,/ }; do
  echo "bench_stage_cost.sh: N = $n under callgrind" >&2
  valgrind --tool=callgrind --callgrind-out-file="$work/cg.$n.out" "${bench[@]}" --n "$n" \
    >/dev/null 2>"$work/valgrind.$n.log"
done
# One fit of OpenCV's model on the same scenes (bench --stage-cost --one-fit), for the table's
# default-path-to-one-fit ratio (issue #12).
if [[ -z "$baseline" ]]; then
  "${bench[@]}" --one-fit --n "$counts" >"$work/one_fit_wall.csv"
  for n in ${counts//,/ }; do
    echo "bench_stage_cost.sh: N = $n, one fit, under callgrind" >&2
    valgrind --tool=callgrind --callgrind-out-file="$work/one_fit.$n.out" "${bench[@]}" \
      --one-fit --n "$n" >/dev/null 2>"$work/valgrind.one_fit.$n.log"
  done
fi

if [[ -n "$baseline" ]]; then
  echo "# $baseline ($(git -C "$root" rev-parse --short "$baseline")), $(valgrind --version)"
  /usr/bin/python3 "$root/scripts/stage_cost.py" totals "$work"
  exit 0
fi
commit=$(git -C "$root" rev-parse --short HEAD)
dirty=$(git -C "$root" status --porcelain --untracked-files=no -- lib apps | grep -q . &&
  echo " with local changes to lib/ or apps/" || true)
cat >"$work/meta.txt" <<META
Commit $commit$dirty, $(date -u +%Y-%m-%d), $(valgrind --version), $(c++ --version | head -1), $(nproc) cores, load average $(cut -d' ' -f1-3 /proc/loadavg). Command: \`bash scripts/bench_stage_cost.sh --n $counts\`.
META
/usr/bin/python3 "$root/scripts/stage_cost.py" table "$work" >"$out"
echo "bench_stage_cost.sh: wrote $out" >&2
