#!/usr/bin/env bash
# Error against run time per fitting method (docs/bench/README.md): builds apps/bench in Release,
# runs it, and writes docs/bench/{results.csv,results.json,table.md,machine.md,error_vs_time.png,
# scaling.png}. Every file is regenerated on each run.
#
# Usage: scripts/bench.sh [bench options]     e.g. scripts/bench.sh --quick --out /tmp/bench
# Without --out the results go to docs/bench. Takes a few minutes on 2 cores (single-threaded).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build="$root/build/release"
cd "$root"

out="docs/bench"
args=("$@")
for ((i = 0; i < ${#args[@]}; ++i)); do
  if [[ "${args[$i]}" == "--out" && $((i + 1)) -lt ${#args[@]} ]]; then out="${args[$((i + 1))]}"; fi
done
if [[ " ${args[*]-} " != *" --out "* ]]; then args+=(--out "$out"); fi

# Release build of the bench alone (scripts/build.sh's configuration).
bash "$root/scripts/build_release.sh" "$build" bench.sh camproj_bench

bench="${build#"$root"/}/apps/bench"
mkdir -p "$out"
command="$bench ${args[*]}"
echo "\$ $command"
load_before=$(cut -d' ' -f1-3 /proc/loadavg)
start=$(date +%s)
status=0
"$bench" "${args[@]}" || status=$?
# 3: results written, but a camproj method failed on a noise-free scene; finish, then report it.
if [[ $status -ne 0 && $status -ne 3 ]]; then exit "$status"; fi
seconds=$(($(date +%s) - start))
load_after=$(cut -d' ' -f1-3 /proc/loadavg)

# The machine and the exact command, next to the results.
version() { dpkg-query -W -f='${Version}' "$1" 2>/dev/null || echo unknown; }
compiler=$(sed -n 's/^CMAKE_CXX_COMPILER:[A-Z]*=//p' "$build/CMakeCache.txt")
lib_changes=$(git status --porcelain -- lib 2>/dev/null | awk '{print $2}' | tr '\n' ' ')
{
  echo "# Machine and command of the benchmark in this directory"
  echo
  echo "Written by \`scripts/bench.sh\`; rerun it to regenerate every file here."
  echo
  echo "| | |"
  echo "|---|---|"
  echo "| date (UTC) | $(date -u +%Y-%m-%dT%H:%M:%SZ) |"
  echo "| command | \`bash scripts/bench.sh${*:+ $*}\`, which ran \`$command\` from the repository root |"
  echo "| wall time | ${seconds} s (single-threaded) |"
  echo "| load average | ${load_before} before, ${load_after} after (1, 5, 15 min; other work on the machine inflates the times) |"
  echo "| git | $(git rev-parse --short HEAD 2>/dev/null || echo unknown)${lib_changes:+ with uncommitted changes in ${lib_changes% }} |"
  echo "| CPU | $(lscpu | sed -n 's/^Model name: *//p' | head -1) |"
  echo "| cores | $(nproc) online ($(lscpu | sed -n 's/^Core(s) per socket: *//p' | head -1) per socket, $(lscpu | sed -n 's/^Thread(s) per core: *//p' | head -1) thread(s) per core, $(lscpu | sed -n 's/^Socket(s): *//p' | head -1) socket(s)); $(lscpu | sed -n 's/^Hypervisor vendor: *//p' | head -1 | sed 's/^\(.\)/virtualized: \1/')|"
  echo "| OS | $(. /etc/os-release && echo "$PRETTY_NAME"), kernel $(uname -r) |"
  echo "| compiler | $("$compiler" --version | head -1), CMAKE_BUILD_TYPE=Release |"
  echo "| OpenCV | $(version libopencv-dev) (libopencv-dev) |"
  echo "| Ceres | $(version libceres-dev) (libceres-dev) |"
  echo "| Eigen | $(version libeigen3-dev) (libeigen3-dev) |"
  echo "| matplotlib | $(version python3-matplotlib) (python3-matplotlib, for the plots) |"
} >"$out/machine.md"

/usr/bin/python3 "$root/scripts/plot_bench.py" "$out"
echo "bench.sh: wrote $out/{results.csv,results.json,table.md,machine.md,error_vs_time.png,scaling.png}"
if [[ $status -ne 0 ]]; then
  echo "bench.sh: the bench's self-check failed (exit $status): see its messages above" >&2
fi
exit "$status"
