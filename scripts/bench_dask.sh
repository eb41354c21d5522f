#!/usr/bin/env bash
# Fits per second on one machine: the same folder of synthetic frames fitted by the batch CLI
# (`camproj fit DIR -o OUT --jobs J`) and by the Dask example (python/examples/dask_fit.py on a
# LocalCluster of J single-threaded workers), per file and in groups of files per task, plus
# the module alone in one process (no Dask) for the floor. Prints a markdown table for
# docs/scale-out.md. Usage: scripts/bench_dask.sh [FRAMES (default 400)] [JOBS (default 2)]
# Each frame: `camproj synth --seed i --points 30 --noise 0.5` (1920x1080).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build="$root/build/release"
frames=${1:-400}
jobs=${2:-2}
bash "$root/scripts/build_release.sh" "$build" bench_dask.sh camproj_cli >/dev/null
bash "$root/scripts/build_release.sh" "$build" bench_dask.sh camproj_python >/dev/null
bin="$build/apps/camproj"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p "$work/frames"
for i in $(seq 1 "$frames"); do
  "$bin" synth --seed "$i" --points 30 --noise 0.5 --image-size 1920x1080 \
    -o "$work/frames/f$(printf %05d "$i").csv" --truth "$work/t.json" >/dev/null
done
rate() { sed -n 's/.*(\([0-9.]*\) fits\/s).*/\1/p'; }
wall() { /usr/bin/python3 -c 'import subprocess, sys, time
t = time.perf_counter(); subprocess.run(sys.argv[1:], stdout=subprocess.DEVNULL, check=False)
print(f"{time.perf_counter() - t:.2f}")' "$@"; }
echo "| how | fits/s as the command reports it (first fit to last file written) | wall time of the whole command, s |"
echo "|---|---:|---:|"
# Exit code 3 (some frames refused) is an outcome here, not a failure of the benchmark.
cli=$( ("$bin" fit "$work/frames" -o "$work/cli" --image-size 1920x1080 --jobs "$jobs" || true) | tail -1 | rate)
echo "| \`camproj fit DIR -o OUT --jobs $jobs\` | $cli | $(wall "$bin" fit "$work/frames" -o "$work/cli" --image-size 1920x1080 --jobs "$jobs") |"
export PYTHONPATH="$build/python"
one=$(/usr/bin/python3 - "$work/frames" <<'PY'
import glob, sys, time
import camproj
files = sorted(glob.glob(sys.argv[1] + "/*.csv"))
t = time.perf_counter()
for f in files:
    try:
        camproj.fit_file(f, (1920, 1080)).to_json()
    except camproj.SceneError:
        pass
print(f"{len(files) / (time.perf_counter() - t):.1f}")
PY
)
echo '| Python module in one process, a loop of `fit_file(...).to_json()` (no Dask, no file written; 1 core) |' "$one | |"
# What writing costs: each camera file is written atomically and flushed to disk (file_io.h).
writes=$(/usr/bin/python3 - "$work/cli" "$work/written" <<'PY'
import glob, os, sys, time
import camproj
texts = [open(f).read() for f in sorted(glob.glob(sys.argv[1] + "/*.json"))]
os.makedirs(sys.argv[2])
t = time.perf_counter()
for i, text in enumerate(texts):
    camproj.write_file_atomically(f"{sys.argv[2]}/{i}.json", text)
print(f"{len(texts) / (time.perf_counter() - t):.1f}")
PY
)
echo '| `camproj.write_file_atomically` of the camera files alone, one thread (files/s) |' "$writes | |"
for k in 1 16; do
  args=("$root/python/examples/dask_fit.py" "$work/frames" -o "$work/dask$k" --image-size 1920x1080 --workers "$jobs" --files-per-task "$k")
  r=$( (/usr/bin/python3 "${args[@]}" || true) | tail -1 | rate)
  echo "| \`python3 python/examples/dask_fit.py DIR -o OUT --workers $jobs --files-per-task $k\` | $r | $(wall /usr/bin/python3 "${args[@]}") |"
done
echo
echo "$frames frames, $(nproc) cores, load average $(cut -d' ' -f1-3 /proc/loadavg), $(date -u +%Y-%m-%d), git $(git -C "$root" rev-parse --short HEAD)"
