#!/usr/bin/env bash
# Installs what is missing, builds, runs every gtest and rostest of sift_hull, checks the install
# space (scripts/install_check.sh), then runs the core gtests again under AddressSanitizer +
# UndefinedBehaviorSanitizer (scripts/sanitize.sh) and each libFuzzer harness for 30 s
# (scripts/fuzz.sh); docs/RELIABILITY.md says more.
# The last line is 'N passed, N failed, N skipped' over all of them; the exit code is non-zero on
# any failure. SIFT_HULL_SANITIZE=0 leaves the sanitizer and fuzz runs out (a quicker local run);
# SIFT_HULL_FUZZ_SECONDS sets the fuzzing time per harness (default 30).
# Real-data tests find ../shared/data (or $SIFT_HULL_DATA) and skip, saying why, without it.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
source "$here/common.sh"

bash "$here/setup.sh"
bash "$here/build.sh" 2>"$workspace/build.log" >/dev/null || {
  tail -n 60 "$workspace/build.log" >&2 || true
  echo "the build failed"
  echo "0 passed, 1 failed"
  exit 1
}
cd "$workspace"
rm -rf build/test_results
log="$workspace/run_tests.log"
if ! catkin_make run_tests -j"$(nproc)" >"$log" 2>&1; then
  tail -n 60 "$log" >&2 || true
  echo "building or running the tests failed"
  echo "0 passed, 1 failed"
  exit 1
fi
echo "install space (scripts/install_check.sh) ..."
bash "$here/install_check.sh" build/test_results/install || true
if [[ "${SIFT_HULL_SANITIZE:-1}" != 0 ]]; then
  # Each writes JUnit XML under build/test_results, counted below with the rest; a failure there
  # is a failed case, so the scripts' own exit codes need not stop this one.
  echo "sanitizer run (scripts/sanitize.sh) ..."
  bash "$here/sanitize.sh" build/test_results/sanitize | tail -n 1 || true
  echo "fuzzing (scripts/fuzz.sh ${SIFT_HULL_FUZZ_SECONDS:-30}) ..."
  bash "$here/fuzz.sh" "${SIFT_HULL_FUZZ_SECONDS:-30}" build/test_results/fuzz | tail -n 1 || true
fi
/usr/bin/python3 "$here/count_tests.py" build/test_results
