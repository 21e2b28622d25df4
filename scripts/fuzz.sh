#!/usr/bin/env bash
# Builds the libFuzzer harnesses of test/fuzz/ (test/sanitize/CMakeLists.txt, target `fuzzers`,
# with AddressSanitizer and UndefinedBehaviorSanitizer, in the git-ignored .sanitize_build/) and
# runs each for SECONDS, FUZZ_PARALLEL (2) at a time.
#
#   scripts/fuzz.sh [SECONDS [RESULTS_DIR]]   (defaults: 30, .sanitize_build/fuzz_results)
#
# Each harness runs with -max_total_time=SECONDS -timeout=10 -rss_limit_mb=2048 on its working
# corpus .sanitize_build/fuzz/corpus/HARNESS/, into which the committed seeds of
# test/fuzz/corpus/HARNESS/ are copied first (the committed corpus is only read; what earlier runs
# added to the working corpus is kept). RESULTS_DIR gets one JUnit case per harness,
# fuzz-HARNESS.xml: passed, or failed with the crashing input's path and the log's tail.
# A crashing, leaking, timed-out or out-of-memory input is copied to
# .sanitize_build/findings/HARNESS-KIND-SHA1 and its path printed, and run once more on its own
# (the first 5) with its report in HARNESS-KIND-SHA1.log beside it; the log of the run is
# .sanitize_build/fuzz/HARNESS.log. The last line is 'N passed, N failed, N skipped'; the exit code
# is non-zero when a harness failed.
#
# Environment:
#   FUZZ_HARNESSES    the harnesses to run (default: all of them), space-separated
#   FUZZ_PARALLEL     harnesses run at once (default 2; their output lines interleave)
#   FUZZ_KEEP_GOING   1: run libFuzzer in fork mode (-fork=1 -ignore_crashes=1 -ignore_timeouts=1
#                     -ignore_ooms=1), collecting every distinct finding within SECONDS instead
#                     of stopping at the first (default 0)
#   SANITIZE_JOBS     build jobs (default 2)
#   SIFT_HULL_SANITIZE_BUILD  the build directory (default .sanitize_build)
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/sanitize_common.sh"

seconds="${1:-30}"
parallel="${FUZZ_PARALLEL:-2}"
[[ "$parallel" =~ ^[1-9][0-9]*$ ]] || { echo "fuzz: FUZZ_PARALLEL must be a positive number" >&2; exit 2; }
[[ "$seconds" =~ ^[1-9][0-9]*$ ]] || { echo "usage: scripts/fuzz.sh [SECONDS [RESULTS_DIR]]" >&2; exit 2; }
results="$(realpath -m "${2:-$sanitize_build/fuzz_results}")"
mkdir -p "$results"
rm -f "$results"/fuzz-*.xml

work="$sanitize_build/fuzz"
findings="$sanitize_build/findings"
mkdir -p "$work" "$findings"
echo "fuzz: building in $sanitize_build (log: $sanitize_build/fuzz_build.log) ..."
build_start=$(date +%s)
if ! build_sanitized fuzzers "$sanitize_build/fuzz_build.log"; then
  tail -n 60 "$sanitize_build/fuzz_build.log" >&2
  "${junit[@]}" case "$results/fuzz-fuzz_build.xml" fuzz build \
    --failure "building the fuzz harnesses failed" --log "$sanitize_build/fuzz_build.log" --tail 60
  echo "building the fuzz harnesses failed"
  echo "0 passed, 1 failed"
  exit 1
fi
echo "fuzz: build took $(($(date +%s) - build_start)) s"
# The build lists every harness of cmake/gtests.cmake (SIFT_HULL_FUZZ_HARNESSES).
harnesses=(${FUZZ_HARNESSES:-$(cat "$sanitize_build/fuzzers.txt")})

export ASAN_OPTIONS=detect_leaks=1:halt_on_error=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
export LSAN_OPTIONS="suppressions=$repo_root/test/sanitize/lsan.supp:print_suppressions=0"
mode=()
[[ "${FUZZ_KEEP_GOING:-0}" == 1 ]] && mode=(-fork=1 -ignore_crashes=1 -ignore_timeouts=1 -ignore_ooms=1)

# One harness: its run, its findings and its JUnit case.
fuzz_one() {
  local harness="$1" seeds corpus artifacts log tmp start rc took saved input base runs pattern
  local report message tail_log replayed line
  seeds="$repo_root/test/fuzz/corpus/$harness"
  corpus="$work/corpus/$harness"
  artifacts="$work/artifacts/$harness"
  log="$work/$harness.log"
  rm -rf "$artifacts"
  mkdir -p "$corpus" "$artifacts"
  [[ -d "$seeds" ]] && cp -n "$seeds"/* "$corpus"/ 2>/dev/null || true
  chmod -R u+w "$corpus"
  tmp="$work/tmp/$harness"
  rm -rf "$tmp" && mkdir -p "$tmp"
  echo "fuzz: $harness for ${seconds} s (log: $log) ..."
  start=$(date +%s)
  rc=0
  # The outer time-out only guards against a libFuzzer that does not stop by itself.
  (cd "$work" && TMPDIR="$tmp" timeout -k 30 $((seconds + 300)) "$sanitize_build/$harness" \
    "${mode[@]}" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 \
    -artifact_prefix="$artifacts/" -print_final_stats=1 "$corpus") >"$log" 2>&1 || rc=$?
  took=$(($(date +%s) - start))
  saved=()
  for input in "$artifacts"/*; do
    [[ -f "$input" ]] || continue
    base="$(basename "$input")"  # crash-SHA1, leak-SHA1, timeout-SHA1, oom-SHA1, slow-unit-SHA1
    [[ "$base" == slow-unit-* ]] && continue
    cp "$input" "$findings/$harness-$base"
    saved+=("$findings/$harness-$base")
  done
  if [[ $rc -eq 0 && ${#saved[@]} -eq 0 ]]; then
    "${junit[@]}" case "$results/fuzz-$harness.xml" fuzz "$harness" --time "$took"
    # Inputs run: the final stats, or in fork mode the last status line '#N: ...'.
    runs="$(grep -oE '^(stat::number_of_executed_units: *[0-9]+|#[0-9]+:)' "$log" | tail -n 1 |
      grep -oE '[0-9]+' || echo '?')"
    echo "fuzz: $harness passed ($runs inputs in ${took} s)"
    return 0
  fi
  pattern='^(SUMMARY: |==[0-9]+== ?ERROR: )|runtime error:|out-of-memory|ALARM'
  report="$(grep -m1 -E "$pattern" "$log" || true)"
  message="$harness failed (exit code $rc)${report:+: $report}"
  tail_log="$log"
  if [[ ${#saved[@]} -gt 0 ]]; then
    message+=$'\n'"crashing input(s):"
    # Each input run once more on its own (the first 5): in fork mode the report is not in $log.
    replayed=0
    for input in "${saved[@]}"; do
      echo "fuzz: $harness: finding saved as $input"
      line=""
      if [[ $replayed -lt 5 ]]; then
        replayed=$((replayed + 1))
        (cd "$work" && TMPDIR="$tmp" timeout -k 10 60 "$sanitize_build/$harness" -timeout=10 \
          -rss_limit_mb=2048 "$input") >"$input.log" 2>&1 || true
        line="$(grep -v '^INFO' "$input.log" | grep -m1 -E "$pattern|returned a bad" || true)"
        [[ -z "$report" ]] && tail_log="$input.log"
      fi
      message+=$'\n'"  $input${line:+: $line}"
    done
  else
    message+=$'\n'"no crashing input was written"
  fi
  "${junit[@]}" case "$results/fuzz-$harness.xml" fuzz "$harness" --failure "$message" \
    --log "$tail_log" --tail 60 --time "$took"
  echo "fuzz: $harness FAILED${report:+: $report}"
}

# FUZZ_PARALLEL harnesses at a time (each libFuzzer process uses one core).
running=0
for harness in "${harnesses[@]}"; do
  if [[ $running -ge $parallel ]]; then
    wait -n || true
    running=$((running - 1))
  fi
  fuzz_one "$harness" &
  running=$((running + 1))
done
wait || true
/usr/bin/python3 "$repo_root/scripts/count_tests.py" "$results"
