#!/usr/bin/env bash
# Memory per point (docs/reliability.md):
# 1. the fit's own: `bench --memory --out docs/bench` (apps/bench/memory.cc) writes
#    docs/bench/memory.md, the peak resident set one fit holds on top of its input, per point;
# 2. the whole `camproj fit` command's: its peak RSS on seeded synthetic scenes of N points
#    (synth, 0.5 px noise; reading the CSV, the ids and the fit), for the default automatic fit
#    and for --model focal, and the slope between the smallest and the largest N in bytes per
#    point (the fixed cost of the binary and its libraries cancels in the slope); printed only.
# Usage: scripts/bench_memory.sh [N...]   (N for part 2; default 100000 400000)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build="$root/build/release"
bash "$root/scripts/build_release.sh" "$build" bench_memory camproj_bench >/dev/null
bash "$root/scripts/build_release.sh" "$build" bench_memory camproj_cli >/dev/null
cd "$root"
echo "\$ build/release/apps/bench --memory --out docs/bench"
"$build/apps/bench" --memory --out docs/bench
echo
echo "The camproj fit command (peak RSS of the process):"
bin="$build/apps/camproj"
sizes=("$@")
((${#sizes[@]} > 0)) || sizes=(100000 400000)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
peak_kb() {  # peak RSS in KB of the command given
  /usr/bin/python3 -c '
import resource, subprocess, sys
subprocess.run(sys.argv[1:], stdout=subprocess.DEVNULL, check=True)
print(resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)' "$@"
}
printf '%-8s %10s %14s %14s\n' model N peak_RSS_MB seconds
for model in auto focal; do
  first_n="" first_kb=""
  for n in "${sizes[@]}"; do
    "$bin" synth --seed 1 --points "$n" --noise 0.5 -o "$work/p.csv" --truth "$work/t.json" >/dev/null
    start=$(date +%s.%N)
    kb=$(peak_kb "$bin" fit "$work/p.csv" --image-size 1920x1080 --model "$model" -o "$work/c.json")
    end=$(date +%s.%N)
    printf '%-8s %10d %14.1f %14.2f\n' "$model" "$n" "$(bc -l <<<"$kb / 1024")" "$(bc -l <<<"$end - $start")"
    if [[ -z "$first_n" ]]; then first_n=$n; first_kb=$kb; fi
    last_n=$n last_kb=$kb
  done
  if ((last_n > first_n)); then
    printf '%-8s slope: %.0f bytes per point\n' "$model" "$(bc -l <<<"($last_kb - $first_kb) * 1024 / ($last_n - $first_n)")"
  fi
done
