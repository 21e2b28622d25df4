#!/usr/bin/env bash
# Builds the core library and its ROS-free gtests with clang under AddressSanitizer and
# UndefinedBehaviorSanitizer (test/sanitize/CMakeLists.txt, in the git-ignored .sanitize_build/)
# and runs every gtest binary there, SANITIZE_PARALLEL of them at a time, the longest first.
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
# Logs: .sanitize_build/logs/NAME.ATTEMPT.log; timings: .sanitize_build/timing.txt. Each binary
# runs in a directory of its own, .sanitize_build/tmp/NAME (its working directory and TMPDIR,
# emptied before each attempt, removed when the binary passed). The binaries start in the order of
# their seconds in the previous run's timing.txt, the longest first; without one (or for a binary
# it does not list) those known to be long (long_first below) come first, then the others in the
# build's order. The lines of binaries running at the same time interleave.
#
# Environment:
#   SIFT_HULL_EXECUTABLE   the catkin-built sift_hull run by the command tests (default: the
#                          workspace's devel/lib/sift_hull/sift_hull; scripts/build.sh builds it
#                          when it is missing); the tests of the benchmarks' commands run the
#                          sift_hull_bench beside it
#   SANITIZE_GTEST_FILTER  a gtest filter for every binary (default '*'); the cases excluded below
#                          stay excluded
#   SANITIZE_TIMEOUT       seconds one binary may run (default 1800)
#   SANITIZE_PARALLEL      binaries run at once (default 2)
#   SANITIZE_ONLY          the binaries to run, space-separated names (default: every one)
#   SANITIZE_JOBS          build jobs (default 2)
#   SIFT_HULL_DATA         the real data sets, as for scripts/test.sh
#   SIFT_HULL_SANITIZE_BUILD  the build directory (default .sanitize_build)
set -euo pipefail  # bash >= 4.3 (wait -n)
source "$(dirname "${BASH_SOURCE[0]}")/sanitize_common.sh"

parallel="${SANITIZE_PARALLEL:-2}"
if [[ ! "$parallel" =~ ^[1-9][0-9]*$ ]]; then
  echo "sanitize: SANITIZE_PARALLEL must be a positive number, not '$parallel'" >&2
  exit 2
fi

results="$(realpath -m "${1:-$sanitize_build/test_results}")"
mkdir -p "$results"
logs="$sanitize_build/logs"
rm -rf "$logs"
mkdir -p "$logs"
timing="$sanitize_build/timing.txt"
# Each binary's seconds (all its attempts) in the previous run's timing.txt, read before this run
# writes it again.
declare -A previous_seconds=()
if [[ -f "$timing" ]]; then
  timing_line='^([^ ]+) attempt [0-9]+: exit [0-9]+, ([0-9]+) s, '
  while IFS= read -r line; do
    if [[ "$line" =~ $timing_line ]]; then
      name="${BASH_REMATCH[1]}"
      previous_seconds[$name]=$((${previous_seconds[$name]:-0} + BASH_REMATCH[2]))
    fi
  done <"$timing"
fi

# Cases left out of the sanitizer run, per binary (gtest negative patterns, ':'-separated).
declare -A excluded=()
# Photo carving's accuracy cases (its depth maps, three scenes carved) take 4 minutes under the
# sanitizers; they run in the ordinary build, and the sanitizers keep the case that runs the whole
# pipeline twice (GivesTheSameVoxelsOnAnyNumberOfThreads) and the small ones.
# PatchMatchFindsMoreTrueDepthsThanTheSweepAlone is an accuracy case too (189 s under the
# sanitizers); the PatchMatch code still runs under them in GivesTheSameVoxelsOnAnyNumberOfThreads.
excluded[test_photo_carving]="ConcaveShapes/*:PhotoCarving.DepthMapsAgreeWithTheRenderedDepth"
excluded[test_photo_carving]+=":PhotoCarving.PatchMatchFindsMoreTrueDepthsThanTheSweepAlone"
# The renderer against its brute-force reference for the sculpture (/0) and the dumbbell (/4) takes
# 47 s and 43 s under the sanitizers; the other six shapes keep the renderer's code paths covered.
excluded[test_scene]="AllShapes/SceneShapes.SilhouetteEqualsProjectionOfAnalyticObject/0"
excluded[test_scene]+=":AllShapes/SceneShapes.SilhouetteEqualsProjectionOfAnalyticObject/4"
# The views silhouettes' accuracy cases on the floor and turntable scenes (9 s and 13 s in the
# ordinary build, each also running the per-image method on every view); the method's code runs
# under the sanitizers in the textured scene's case and the contradicted view's.
excluded[test_view_silhouettes]="ViewSilhouettes.FloorWithShadowsBeatsThePerImageMethod"
excluded[test_view_silhouettes]+=":ViewSilhouettes.TurntableBeatsThePerImageMethod"
excluded[test_silhouette_choice]="SilhouetteChoice.FloorWithShadowsTakesTheViewsMethod"
excluded[test_silhouette_choice]+=":SilhouetteChoice.ViewsArrivingOneAtATimeAreSegmentedTogetherAsTheSetGrows"
# Accuracy studies whose slow part is the test's own reference, on code the sanitizers run in
# other cases: the cut shapes' depth maps against fine sampling along every ray (160 s; the cup
# and U-block are rendered under the sanitizers in test_refine and test_point_carved_stream), the
# Middlebury rings with the background method (60 s; the method runs on every background in
# ComeCloseToTheExactMasksOnEveryBackground), the distorted 1600x1200 set at depth 8 (44 s; the
# reduced maps run in test_reduced_distance, the distortion in the other cases) and the pocket
# left by exact covisible points (65 s; carving with points runs in test_refine), and photographs
# segmented at full resolution to compare with their reduced reading (the reduced reading runs in
# ReducedPhotoHullInput.ReadsAndSegmentsEachViewAtTheReduction).
excluded[test_cut_shapes]="Shape.CutShapesAreRenderedWhereTheirRaysFirstEnterTheSolid"
excluded[test_silhouettes]="BackgroundSilhouettes.GiveTheMiddleburyRingsTheirHullWithoutAThreshold"
excluded[test_distorted_scene]="DistortedScene.ReducedDistanceMapsKeepTheHullOfADistortedHighResolutionSet"
excluded[test_dense_matching]="PairCovisiblePoints.CarveLessOfThePocketThanEachViewsOwnPoints"
excluded[test_reduced_photographs]="ReducedPhotoHullInput.SegmentsAsWellAsAtFullResolution"
# The binaries that took longest under the sanitizers, the longest first: they start first when
# no earlier timing.txt gives the binaries' seconds.
long_first=(test_photo_carving test_scene test_photo_stream test_point_carved_stream test_cut_shapes
  test_hull test_dense_matching test_refine test_distorted_scene)
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
if [[ -n "${SANITIZE_ONLY:-}" ]]; then
  declare -A only=()
  read -r -a only_names <<<"$SANITIZE_ONLY"
  for name in "${only_names[@]}"; do only[$name]=1; done
  selected=()
  for name in "${gtests[@]}"; do
    if [[ -n "${only[$name]:-}" ]]; then
      selected+=("$name")
      unset "only[$name]"
    fi
  done
  for name in "${!only[@]}"; do
    echo "sanitize: SANITIZE_ONLY names $name, which $sanitize_build/gtests.txt does not list" >&2
  done
  gtests=("${selected[@]}")
fi
# The order in which they start: those with seconds in the previous timing.txt by those seconds,
# the longest first; before them those of long_first it does not list, in that order; after them
# the others, in the build's order.
declare -A long_rank=()
for index in "${!long_first[@]}"; do long_rank[${long_first[$index]}]=$index; done
mapfile -t gtests < <(
  for index in "${!gtests[@]}"; do
    name="${gtests[$index]}"
    if [[ -n "${previous_seconds[$name]:-}" ]]; then
      echo "1 $((-previous_seconds[$name])) $index $name"
    elif [[ -n "${long_rank[$name]:-}" ]]; then
      echo "0 ${long_rank[$name]} $index $name"
    else
      echo "2 0 $index $name"
    fi
  done | sort -k1,1n -k2,2n -k3,3n | cut -d' ' -f4
)

export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1:halt_on_error=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
export LSAN_OPTIONS="suppressions=$repo_root/test/sanitize/lsan.supp:print_suppressions=1"
# The binaries' own directories (tmp/NAME) and their verdicts (tmp/NAME.status, passed or FAILED).
scratch_root="$sanitize_build/tmp"
rm -rf "$scratch_root"
mkdir -p "$scratch_root"
timeout_s="${SANITIZE_TIMEOUT:-1800}"
echo "build ${build_seconds} s (target gtests, -j${SANITIZE_JOBS:-2})" >"$timing"

# Runs one binary (see the header) in the directory $2; creates the file $3 when it passed.
run_gtest() {
  local name="$1" binary="$sanitize_build/$1" scratch="$2" passed_file="$3" dead=() attempt
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
      if [[ ${#dead[@]} -eq 0 ]]; then : >"$passed_file"; fi
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

# Runs one binary as a background job (a subshell of its own: it shares no variable with the
# others); prints its line and writes tmp/NAME.status last.
run_binary() {
  local name="$1" start verdict=FAILED
  local scratch="$scratch_root/$name" passed_file="$scratch_root/$name.passed"
  start=$(date +%s)
  run_gtest "$name" "$scratch" "$passed_file"
  if [[ -e "$passed_file" ]]; then
    verdict=passed
    rm -rf "$scratch"
  fi
  echo "sanitize: $name $verdict in $(($(date +%s) - start)) s"
  echo "$verdict" >"$scratch_root/$name.status"
}

# Interrupted, the script stops the jobs with it (a binary already started runs to its end, as it
# did when the binaries ran one after the other).
stop_jobs() {
  local pids
  pids="$(jobs -p)"
  # shellcheck disable=SC2086  # one pid a word
  if [[ -n "$pids" ]]; then kill $pids 2>/dev/null || true; fi
}
trap 'stop_jobs; exit 130' INT
trap 'stop_jobs; exit 143' TERM

echo "sanitize: running ${#gtests[@]} gtest binaries, $parallel at a time (logs: $logs) ..."
echo "sanitize: in this order: ${gtests[*]}"
run_start=$(date +%s)
busy=0  # jobs started and not yet waited for
for name in "${gtests[@]}"; do
  if ((busy >= parallel)); then
    wait -n || true  # the job's own status: see tmp/NAME.status below
    busy=$((busy - 1))
  fi
  run_binary "$name" &
  busy=$((busy + 1))
done
wait || true
run_seconds=$(($(date +%s) - run_start))
# A job without a status stopped on an error in this script (set -e) rather than in its binary.
for name in "${gtests[@]}"; do
  if [[ ! -f "$scratch_root/$name.status" ]]; then
    echo "sanitize: the run of $name stopped on an error in scripts/sanitize.sh" >&2
    "${junit[@]}" case "$results/$name.script.xml" "$name" sanitize_script \
      --failure "scripts/sanitize.sh stopped on an error while running $name"
  fi
done
echo "gtests ${run_seconds} s in all" >>"$timing"
echo "sanitize: build ${build_seconds} s, gtest run ${run_seconds} s (details: $timing)"
/usr/bin/python3 "$repo_root/scripts/count_tests.py" "$results"
