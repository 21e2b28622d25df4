#!/usr/bin/env bash
# Installs what is missing, builds, and runs every gtest and rostest of sift_hull.
# The last line is 'N passed, N failed, N skipped'; the exit code is non-zero on any failure.
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
/usr/bin/python3 "$here/count_tests.py" build/test_results
