#!/usr/bin/env bash
# Builds the libFuzzer targets of fuzz/ in the sanitizer build (build/sanitize, clang:
# scripts/build_sanitize.sh, shared with `scripts/test.sh --sanitize`), replays each seed corpus, then
# fuzzes each target for SECONDS seconds (default 30; or CAMPROJ_FUZZ_SECONDS) on a temporary
# copy of its corpus (the committed corpus is never modified).
# Usage: scripts/fuzz.sh [SECONDS]
# Prints one line per target on success. On a crash, leak, UB, timeout or escaped exception it
# prints the fuzzer's log and where the reproducer is saved, and exits non-zero.
# Reproduce: build/sanitize/fuzz/<target>_fuzzer <reproducer file>
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build="$root/build/sanitize"
seconds=${1:-${CAMPROJ_FUZZ_SECONDS:-30}}
if ! [[ "$seconds" =~ ^[0-9]+$ ]] || ((seconds < 1)); then
  echo "fuzz: SECONDS must be a positive integer, got '$seconds'" >&2
  exit 1
fi
mkdir -p "$build"
logs="$build/fuzz-logs"
mkdir -p "$logs"

targets=(points_csv camera_json fit_scene)
if ! bash "$root/scripts/build_sanitize.sh" "${targets[@]/%/_fuzzer}" >"$logs/build.log" 2>&1; then
  cat "$logs/build.log" >&2
  echo "fuzz: building the fuzzers in $build failed" >&2
  exit 1
fi

export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1}
run_id=$(date +%Y%m%d-%H%M%S)
artifacts="$build/artifacts/$run_id"
work=$(mktemp -d "${TMPDIR:-/tmp}/camproj-fuzz.XXXXXX")
trap 'rm -rf "$work"' EXIT
# Bounds: -timeout reports an input that takes longer than that (a hang); -max_len 64 KiB, but
# for the camera-file reader its own size limit, 1 MiB: a deep nesting needs ~130 KB to crash a
# recursive reader (issue #11); and 4 KiB for the fitter's scenes, which read ~400 bytes at most.
# The fitter's -timeout is 60 s: a scene of random pixels takes LO-RANSAC ~0.6 s in Release and
# ~10 s under the sanitizers (measured); a hang is far beyond either.
common=(-rss_limit_mb=2048)
declare -A max_len=([points_csv]=65536 [camera_json]=1048576 [fit_scene]=4096)
declare -A timeout=([points_csv]=10 [camera_json]=10 [fit_scene]=60)

# Prints a failed step's log and the reproducers it left; $1 target, $2 step, $3 exit code, $4 log.
report_failure() {
  local target=$1 step=$2 code=$3 log=$4
  mkdir -p "$artifacts/$target"
  cp "$log" "$artifacts/$target/"
  {
    echo "======== fuzz: $target: $step FAILED (exit $code); log (without progress lines) ========"
    grep -v -E '^#[0-9]+[[:space:]]+(NEW|REDUCE|pulse|RELOAD)[[:space:]]' "$log" || true
    echo "======== end of log ========"
    echo "fuzz: $target: $step failed; log: $artifacts/$target/$(basename "$log")"
    local found=0 file
    for file in "$artifacts/$target"/{crash,leak,timeout,oom,slow-unit}-*; do
      [[ -e "$file" ]] || continue
      found=1
      echo "fuzz: $target: reproducer: $file"
      echo "fuzz: $target:   rerun: $build/fuzz/${target}_fuzzer $file"
    done
    # Replaying files one by one writes no artifact: the input is the last one the log names.
    file=$(sed -n 's/^Running: //p' "$log" | tail -n 1)
    if ((found == 0)) && [[ -n "$file" ]]; then
      found=1
      echo "fuzz: $target: reproducer: $file"
      echo "fuzz: $target:   rerun: $build/fuzz/${target}_fuzzer $file"
    fi
    if ((found == 0)); then
      echo "fuzz: $target: no reproducer file was written; see the log"
    fi
  } >&2
}

failed=0
for target in "${targets[@]}"; do
  fuzzer="$build/fuzz/${target}_fuzzer"
  corpus="$root/fuzz/corpus/$target"
  mkdir -p "$artifacts/$target"
  prefix=(-artifact_prefix="$artifacts/$target/" -max_len="${max_len[$target]}"
          -timeout="${timeout[$target]}")

  # Replay: every seed once, each on its own (a crashing seed is named in the log).
  seeds=("$corpus"/*)
  log="$logs/$target.replay.log"
  code=0
  "$fuzzer" -runs=0 "${common[@]}" "${prefix[@]}" "${seeds[@]}" >"$log" 2>&1 || code=$?
  if ((code != 0)); then
    report_failure "$target" "replaying the seed corpus" "$code" "$log"
    failed=1
    continue
  fi

  # Fuzz on a copy of the corpus, which libFuzzer grows with the inputs it finds.
  mkdir -p "$work/$target"
  cp "${seeds[@]}" "$work/$target/"
  log="$logs/$target.fuzz.log"
  code=0
  dict=()  # the parsers' tokens; the fitter's scenes are numbers, it has none
  [[ -f "$root/fuzz/$target.dict" ]] && dict=(-dict="$root/fuzz/$target.dict")
  "$fuzzer" "$work/$target" -max_total_time="$seconds" -print_final_stats=1 \
    "${dict[@]}" "${common[@]}" "${prefix[@]}" >"$log" 2>&1 || code=$?
  if ((code != 0)); then
    report_failure "$target" "fuzzing" "$code" "$log"
    failed=1
    continue
  fi
  done_line=$(grep -E '^#[0-9]+[[:space:]]+DONE' "$log" | tail -n 1 || true)
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log")
  per_second=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log")
  rss=$(sed -n 's/^stat::peak_rss_mb: *//p' "$log")
  cov=$(sed -n 's/.* cov: \([0-9]*\).*/\1/p' <<<"$done_line")
  ft=$(sed -n 's/.* ft: \([0-9]*\).*/\1/p' <<<"$done_line")
  corp=$(sed -n 's/.* corp: \([0-9]*\)\/.*/\1/p' <<<"$done_line")
  echo "fuzz: $target: ok, ${seconds} s, ${execs:-?} execs (${per_second:-?}/s), cov ${cov:-?}," \
       "ft ${ft:-?}, corpus ${#seeds[@]} seeds -> ${corp:-?}, rss ${rss:-?} MB"
  rmdir "$artifacts/$target" 2>/dev/null || true
done
rmdir "$artifacts" "$build/artifacts" 2>/dev/null || true
exit "$failed"
