#!/usr/bin/env bash
# Builds the libFuzzer programs (the fuzz preset: clang, ASan + UBSan) and runs each for a bounded time from its
# corpus in tests/fuzz/corpus/. New inputs go to a scratch directory, not into the repository; a crash, a
# sanitizer report or a hang (one input running over 10 s) fails the run, and libFuzzer writes the input as
# crash-*/timeout-* into build/fuzz/findings/.
# Usage: bash tools/fuzz.sh [SECONDS_PER_TARGET]   (default 60)
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-60}"
cmake --preset fuzz >/dev/null
cmake --build --preset fuzz
findings=build/fuzz/findings
mkdir -p "$findings"
for target in scene_loader trace_ray; do
  scratch=$(mktemp -d)
  echo "fuzz: $target for ${seconds}s"
  # -rss_limit_mb: the loader must refuse absurd sizes before allocating them.
  log="$findings/$target.log"
  status=0
  (cd "$findings" && ASAN_OPTIONS=detect_leaks=0 "../tests/fuzz/refray_fuzz_$target" -max_total_time="$seconds" \
      -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 "$scratch" "../../../tests/fuzz/corpus/$target") \
      >"$log" 2>&1 || status=$?
  grep -E "^stat::number_of_executed_units|ERROR|SUMMARY|Test unit written" "$log" || true
  rm -rf "$scratch"
  if [ "$status" -ne 0 ]; then
    echo "fuzz: $target found a problem (exit $status); the input is in $findings" >&2
    exit 1
  fi
done
echo "fuzz: no findings"
