#!/usr/bin/env bash
# Builds the core library and its ROS-free gtests with clang under AddressSanitizer and
# UndefinedBehaviorSanitizer (test/sanitize/CMakeLists.txt, in the git-ignored .sanitize_build/)
# and runs every gtest binary there, one after the other.
#
#   scripts/sanitize.sh [RESULTS_DIR]      (default: .sanitize_build/test_results)
#
# The binaries are those test/sanitize/CMakeLists.txt lists (SIFT_HULL_GTESTS: the core gtests,
# which need no ROS). Each writes its gtest XML to RESULTS_DIR/NAME.xml (the test_*.xml files of an
# earlier run there are removed first); scripts/count_tests.py counts them and
# prints the last line, 'N passed, N failed, N skipped'; the exit code is non-zero on any failure.
# A sanitizer report aborts the process (ASAN_OPTIONS below). A binary that died in a case gets a
# failing case NAME.died-K.xml naming it and the log's tail, and is run again without that case
# (at most 4 times) so that its other cases are still checked; one that exited non-zero after
# writing an XML without failures (a leak found at exit) gets a failing case NAME.exit.xml.
# Logs: .sanitize_build/logs/NAME.ATTEMPT.log; timings: .sanitize_build/timing.txt.
#
# Environment:
#   SIFT_HULL_EXECUTABLE   the catkin-built sift_hull run by the command tests (default: the
#                          workspace's devel/lib/sift_hull/sift_hull; scripts/build.sh builds it
#                          when it is missing); the tests of the benchmarks' commands run the
#                          sift_hull_bench beside it
#   SANITIZE_GTEST_FILTER  a gtest filter for every binary (default '*'); the cases excluded below
#                          stay excluded
#   SANITIZE_TIMEOUT       seconds one binary may run (default 1800)
#   SANITIZE_JOBS          build jobs (default 2)
#   SIFT_HULL_DATA         the real data sets, as for scripts/test.sh
#   SIFT_HULL_SANITIZE_BUILD  the build directory (default .sanitize_build)
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/sanitize_common.sh"

results="$(realpath -m "${1:-$sanitize_build/test_results}")"
mkdir -p "$results"
logs="$sanitize_build/logs"
rm -rf "$logs"
mkdir -p "$logs"

# Cases left out of the sanitizer run, per binary (gtest negative patterns, ':'-separated).
declare -A excluded=()
# Photo carving's accuracy cases (its depth maps, three scenes carved) take 4 minutes under the
# sanitizers; they run in the ordinary build, and the sanitizers keep the case that runs the whole
# pipeline twice (GivesTheSameVoxelsOnAnyNumberOfThreads) and the small ones.
excluded[test_photo_carving]="ConcaveShapes/*:PhotoCarving.DepthMapsAgreeWithTheRenderedDepth"
# The XML files of an earlier run (this script writes test_*.xml and sanitize_build.xml only).
rm -f "$results"/test_*.xml "$results/sanitize_build.xml"

executable="${SIFT_HULL_EXECUTABLE:-$workspace/devel/lib/sift_hull/sift_hull}"
if [[ ! -x "$executable" ]]; then
  echo "sanitize: $executable is missing; building it with scripts/build.sh" >&2
  executable="$(bash "$repo_root/scripts/build.sh" 2>"$sanitize_build/catkin_build.log" | tail -n 1)" || {
    tail -n 40 "$sanitize_build/catkin_build.log" >&2
    echo "sanitize: scripts/build.sh failed; the command tests will fail" >&2
  }
fi

echo "sanitize: building in $sanitize_build (log: $sanitize_build/build.log) ..."
build_start=$(date +%s)
if ! build_sanitized gtests "$sanitize_build/build.log" -DSIFT_HULL_EXECUTABLE="$executable" \
  -DSIFT_HULL_BENCH_EXECUTABLE="$(dirname "$executable")/sift_hull_bench"; then
  tail -n 60 "$sanitize_build/build.log" >&2
  "${junit[@]}" case "$results/sanitize_build.xml" sanitize build \
    --failure "the sanitizer build failed" --log "$sanitize_build/build.log" --tail 60
  echo "the sanitizer build failed"
  echo "0 passed, 1 failed"
  exit 1
fi
build_seconds=$(($(date +%s) - build_start))
echo "sanitize: build took ${build_seconds} s"
# The binaries test/sanitize/CMakeLists.txt builds (SIFT_HULL_GTESTS).
mapfile -t gtests < <(grep -v '^$' "$sanitize_build/gtests.txt")

export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1:halt_on_error=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
export LSAN_OPTIONS="suppressions=$repo_root/test/sanitize/lsan.supp:print_suppressions=1"
scratch="$sanitize_build/tmp"
timeout_s="${SANITIZE_TIMEOUT:-1800}"
timing="$sanitize_build/timing.txt"
echo "build ${build_seconds} s (target gtests, -j${SANITIZE_JOBS:-2})" >"$timing"

# Runs one binary (see the header); sets $status to 0 when it passed.
run_gtest() {
  local name="$1" binary="$sanitize_build/$1" dead=() attempt
  status=1
  for attempt in 1 2 3 4; do
    local negative="${excluded[$name]:-}" case_name
    for case_name in "${dead[@]}"; do negative="${negative:+$negative:}$case_name"; done
    local filter="${SANITIZE_GTEST_FILTER:-*}${negative:+-$negative}"
    local xml="$results/$name.xml" log="$logs/$name.$attempt.log" rc=0 start
    rm -f "$xml"
    rm -rf "$scratch" && mkdir -p "$scratch"
    start=$(date +%s)
    (cd "$scratch" && TMPDIR="$scratch" timeout -k 30 "$timeout_s" "$binary" \
      --gtest_filter="$filter" --gtest_output="xml:$xml") >"$log" 2>&1 || rc=$?
    local seconds=$(($(date +%s) - start)) failures=""
    echo "$name attempt $attempt: exit $rc, ${seconds} s, filter '$filter'" >>"$timing"
    failures="$("${junit[@]}" failures "$xml" 2>/dev/null)" || failures=""
    if [[ $rc -eq 0 && -n "$failures" ]]; then
      if [[ ${#dead[@]} -eq 0 ]]; then status=0; fi
      return 0
    fi
    local why="exit code $rc"
    [[ $rc -eq 124 || $rc -eq 137 ]] && why="killed after the ${timeout_s} s time-out"
    [[ $rc -eq 134 ]] && why="aborted (exit code 134: a sanitizer report or an abort)"
    local report
    report="$(grep -m1 -E '^(SUMMARY: |==[0-9]+==ERROR: )|runtime error:' "$log" || true)"
    if [[ -n "$failures" ]]; then
      # Every case ran and reported; a sanitizer report at exit (a leak) does not show in the XML.
      if [[ "$failures" == 0 || -n "$report" ]]; then
        "${junit[@]}" case "$results/$name.exit.xml" "$name" process_exit \
          --failure "$name ended with $why after its cases ran${report:+: $report}" --log "$log" \
          --tail 80 --time "$seconds"
      fi
      return 0
    fi
    local running
    running="$("${junit[@]}" running "$log")"
    if [[ -z "$running" ]]; then
      "${junit[@]}" case "$results/$name.died.xml" "$name" process \
        --failure "$name died outside any test case: $why${report:+: $report}" --log "$log" \
        --tail 80 --time "$seconds"
      return 0
    fi
    "${junit[@]}" case "$results/$name.died-$attempt.xml" "${running%%.*}" "${running#*.}" \
      --failure "$name died in $running: $why${report:+: $report}" --log "$log" --tail 80 \
      --time "$seconds"
    echo "sanitize: $name died in $running ($why); log: $log" >&2
    dead+=("$running")
  done
  return 0
}

echo "sanitize: running ${#gtests[@]} gtest binaries (logs: $logs) ..."
run_start=$(date +%s)
for name in "${gtests[@]}"; do
  start=$(date +%s)
  run_gtest "$name"
  echo "sanitize: $name $([[ $status -eq 0 ]] && echo passed || echo FAILED) in $(($(date +%s) - start)) s"
done
run_seconds=$(($(date +%s) - run_start))
echo "gtests ${run_seconds} s in all" >>"$timing"
echo "sanitize: build ${build_seconds} s, gtest run ${run_seconds} s (details: $timing)"
/usr/bin/python3 "$repo_root/scripts/count_tests.py" "$results"
