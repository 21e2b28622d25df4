#!/usr/bin/env bash
# Builds sift_hull with catkin in a git-ignored workspace (.catkin_ws, or $SIFT_HULL_WORKSPACE).
# Release by default (BUILD_TYPE=Debug to change). Build output goes to stderr; the last line on
# stdout is the absolute path of the built sift_hull executable.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"

# The package in the workspace is a folder of links to the checkout's entries, the workspace left
# out: a link to the whole checkout would hold the workspace inside itself, and rosrun's search
# (find -L) would loop. Refreshed on every build, so that new top-level entries appear.
package="$workspace/src/sift_hull"
mkdir -p "$workspace/src"
[[ -L "$package" ]] && rm "$package"  # the single link of earlier builds
mkdir -p "$package"
find "$package" -mindepth 1 -maxdepth 1 -type l -delete
for entry in "$repo_root"/* "$repo_root"/.clang-format; do
  [[ -e "$entry" ]] || continue
  # Left out: any entry that holds the workspace (SIFT_HULL_WORKSPACE may lie deeper inside).
  [[ "$workspace/" == "$(realpath "$entry")/"* ]] && continue
  ln -sfn "$entry" "$package/"
done
cd "$workspace"
catkin_make -DCMAKE_BUILD_TYPE="${BUILD_TYPE:-Release}" -DPYTHON_EXECUTABLE=/usr/bin/python3 \
  -DCATKIN_ENABLE_TESTING=ON -j"$(nproc)" "$@" >&2
echo "$workspace/devel/lib/sift_hull/sift_hull"
