#!/usr/bin/env bash
# Builds the libFuzzer targets (tests/fuzz, clang with ASan + UBSan) and runs each for its
# share of SECONDS, starting from the seed corpus in tests/fuzz/corpus/<target> and growing a
# working corpus in BUILD/corpus/<target>. Any crash, leak, sanitizer report or timeout stops
# the run with status 1; the input that caused it is saved in BUILD/crashes/.
#   scripts/fuzz.sh [SECONDS] [BUILD]     (default 60 s in build-fuzz)
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
build=${2:-build-fuzz}
targets=(messages config weather_map metar)

cmake -S tests/fuzz -B "$build" -DCMAKE_C_COMPILER=clang -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
cmake --build "$build" -j"$(nproc)" >/dev/null

share=$(( seconds / ${#targets[@]} ))
[ "$share" -ge 1 ] || share=1
mkdir -p "$build/crashes"
status=0
for t in "${targets[@]}"; do
  corpus="$build/corpus/$t"
  mkdir -p "$corpus"
  log="$build/fuzz_$t.log"
  # -max_len: messages up to 64 KiB (max_message_bytes); the rest need less to reach their code
  # (4 KiB is four times the longest METAR the decoder reads).
  max_len=4096
  [ "$t" = messages ] && max_len=65536
  if UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1 ASAN_OPTIONS=detect_leaks=1 \
     "$build/fuzz_$t" "$corpus" "tests/fuzz/corpus/$t" -max_total_time="$share" \
       -max_len="$max_len" -timeout=10 -rss_limit_mb=2048 -error_exitcode=1 \
       -artifact_prefix="$build/crashes/$t-" -print_final_stats=1 >"$log" 2>&1; then
    runs=$(sed -nE 's/^stat::number_of_executed_units: *([0-9]+).*/\1/p' "$log")
    cov=$(grep -oE 'cov: [0-9]+' "$log" | tail -1)
    echo "fuzz $t: ${share} s, ${runs:-?} inputs, $cov, no crash"
  else
    echo "fuzz $t: FAILED (log $log, inputs in $build/crashes/)" >&2
    tail -40 "$log" >&2
    status=1
  fi
done
exit $status
