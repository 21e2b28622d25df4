#!/usr/bin/env bash
# Builds sift_hull with catkin in a git-ignored workspace (.catkin_ws, or $SIFT_HULL_WORKSPACE).
# Release by default (BUILD_TYPE=Debug to change). Build output goes to stderr; the last line on
# stdout is the absolute path of the built sift_hull executable.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"

mkdir -p "$workspace/src"
ln -sfn "$repo_root" "$workspace/src/sift_hull"
cd "$workspace"
catkin_make -DCMAKE_BUILD_TYPE="${BUILD_TYPE:-Release}" -DPYTHON_EXECUTABLE=/usr/bin/python3 \
  -DCATKIN_ENABLE_TESTING=ON -j"$(nproc)" "$@" >&2
echo "$workspace/devel/lib/sift_hull/sift_hull"
