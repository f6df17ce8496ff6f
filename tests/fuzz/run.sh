#!/usr/bin/env bash
# Runs every libFuzzer target for a bounded time, two at a time (JOBS), starting from the seeds in
# the repository.
#   tests/fuzz/run.sh BUILD_DIR [SECONDS_PER_TARGET]   (default 60)
# A crash, a sanitizer report, a leak, a timeout (10 s per input) or running out of memory (2 GiB)
# fails the script; the input is left in BUILD_DIR/fuzz/findings/ and printed as a hint. To keep it
# as a regression input, copy it to tests/data/fuzz/<target>/ after fixing the bug.
set -euo pipefail
cd "$(dirname "$0")/../.."
build=$1
seconds=${2:-60}
work=$build/fuzz
rm -rf "$work"
mkdir -p "$work/findings"
declare -A seeds=(
  [scene]="tests/data/valid tests/data/invalid tests/data/fuzz/scene"
  [artifact]="examples/artifacts tests/data/fuzz/artifact"
  [robot]="examples/robots/simple tests/data/fuzz/robot"
  [parameter]="tests/data/fuzz/parameter"
  [state]="tests/data/fuzz/state"
  [command_line]="tests/data/fuzz/command_line"
  [recording]="tests/data/fuzz/recording"
)
# one target: its findings and counts into $work/$target.log, its verdict into $work/$target.status
fuzz_one() {
  local target=$1 corpus=$work/corpus_$1
  mkdir -p "$corpus"
  # shellcheck disable=SC2086
  if "$build/bin/ssx_${target}_fuzz" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 \
      -artifact_prefix="$work/findings/${target}_" -print_final_stats=1 "$corpus" ${seeds[$target]} \
      > "$work/$target.log" 2>&1; then
    echo ok > "$work/$target.status"
  else
    echo finding > "$work/$target.status"
  fi
}
# JOBS targets at a time (default 2; each fuzzer runs on one core)
jobs=${JOBS:-2}
targets=(scene artifact robot parameter state command_line recording)
running=0
for target in "${targets[@]}"; do
  fuzz_one "$target" &
  running=$((running + 1))
  if [ "$running" -ge "$jobs" ]; then
    wait -n
    running=$((running - 1))
  fi
done
wait
status=0
for target in "${targets[@]}"; do
  if [ "$(cat "$work/$target.status" 2>/dev/null)" != ok ]; then
    echo "fuzz: $target: FINDING (log: $work/$target.log)"
    grep -E "ERROR|SUMMARY|Test unit written" "$work/$target.log" | head -20
    status=1
  else
    runs=$(grep -o "stat::number_of_executed_units: *[0-9]*" "$work/$target.log" | grep -o "[0-9]*$" || echo "?")
    echo "fuzz: $target: ${seconds} s, $runs inputs, no finding"
  fi
done
exit $status
