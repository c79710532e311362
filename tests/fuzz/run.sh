#!/usr/bin/env bash
# Runs one libFuzzer target: first every committed regression input once, then fuzzing for
# SECONDS from the committed seeds (new inputs go to a scratch corpus, never into the repo).
# Prints the executions; a crash fails the test and leaves its input in the scratch directory.
#   run.sh FUZZER NAME SECONDS
set -euo pipefail
fuzzer=$1 name=$2 seconds=$3
here=$(cd "$(dirname "$0")" && pwd)
scratch=$(mktemp -d "/tmp/effectd-fuzz-$name.XXXXXX")
# Full malloc stacks, so that LeakSanitizer attributes library allocations (tests/lsan.supp).
export ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}fast_unwind_on_malloc=0"
regressions="$here/regressions/$name"
if [ -d "$regressions" ] && [ -n "$(ls -A "$regressions")" ]; then
  "$fuzzer" -runs=1 "$regressions"/* >/dev/null 2>"$scratch/regressions.log" || { cat "$scratch/regressions.log"; exit 1; }
fi
"$fuzzer" -max_total_time="$seconds" -rss_limit_mb=2048 -timeout=10 -max_len=65536 -print_final_stats=1 \
  -artifact_prefix="$scratch/" "$scratch" "$here/seeds/$name" >"$scratch/log" 2>&1 || { tail -60 "$scratch/log"; exit 1; }
execs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$scratch/log" | grep -o '[0-9]*$')
cov=$(grep -o 'cov: [0-9]*' "$scratch/log" | tail -1)
echo "fuzz_$name: $execs executions in ${seconds} s, $cov"
rm -rf "$scratch"
