#!/usr/bin/env bash
# Runs every libFuzzer program of BUILD/bin (Fuzz*) for SECONDS each, FUZZ_JOBS
# (default 2) at a time, each on its working corpus BUILD/fuzz/corpus/<Name> (kept between
# runs, seeded from Corpus/<Name> and Regressions/<Name>). A crash, hang
# (over 10 s on one input), leak, sanitizer report or allocation over 1 GiB
# leaves its input in BUILD/fuzz/findings/<Name>/ and makes this script exit 1.
# Prints each target's executions, and appends them to BUILD/fuzz/stats.tsv
# (time, target, seconds run, executions, exit code).
# Usage: run_fuzzers.sh BUILD SECONDS [NAME...]
set -uo pipefail
build=$1 seconds=$2
shift 2
here=$(cd "$(dirname "$0")" && pwd)
names=("$@")
if [ ${#names[@]} -eq 0 ]; then
  for program in "$build"/bin/Fuzz*; do names+=("$(basename "$program" | sed 's/^Fuzz//')"); done
fi
[ ${#names[@]} -gt 0 ] || { echo "no fuzz programs in $build/bin" >&2; exit 1; }
mkdir -p "$build/fuzz/logs" "$build/fuzz/scratch"
# Inputs become files on a tmpfs when there is one (the readers take paths).
scratch=/dev/shm
[ -d "$scratch" ] && [ -w "$scratch" ] || scratch="$build/fuzz/scratch"

run_one() {
  local name=$1 build=$2 seconds=$3 here=$4 scratch=$5
  local corpus="$build/fuzz/corpus/$name" findings="$build/fuzz/findings/$name/"
  mkdir -p "$corpus" "$findings"
  cp -n "$here/Corpus/$name"/* "$corpus"/ 2>/dev/null
  [ -d "$here/Regressions/$name" ] && cp -n "$here/Regressions/$name"/* "$corpus"/ 2>/dev/null
  rm -f "$corpus/README.md"
  local log="$build/fuzz/logs/$name.log" started
  started=$(date +%s)
  TMPDIR="$scratch" \
  ASAN_OPTIONS=detect_leaks=1:allocator_may_return_null=1 \
  LSAN_OPTIONS=suppressions="$here/../Sanitizers/lsan.supp" \
  UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1 \
    "$build/bin/Fuzz$name" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -malloc_limit_mb=1024 \
      -max_len=16384 -print_final_stats=1 -artifact_prefix="$findings" "$corpus" >"$log" 2>&1
  local rc=$? elapsed=$(($(date +%s) - started))
  local runs
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  printf '%s\t%s\t%s\t%s\t%s\n' "$(date -u +%FT%TZ)" "$name" "$elapsed" "${runs:-0}" "$rc" >>"$build/fuzz/stats.tsv"
  if [ $rc -eq 0 ]; then
    printf '%-14s %10s executions in %s s, no finding\n' "$name" "${runs:-?}" "$seconds"
  else
    printf '%-14s FAILED (exit %s): see %s, inputs in %s\n' "$name" "$rc" "$log" "$findings"
    grep -E "^==[0-9]+==ERROR|SUMMARY|runtime error|Deadly|timeout|out-of-memory|malloc\(" "$log" | head -5
  fi
  return $rc
}
export -f run_one

printf '%s\n' "${names[@]}" |
  xargs -P "${FUZZ_JOBS:-2}" -I{} bash -c 'run_one "$@"' _ {} "$build" "$seconds" "$here" "$scratch"
