#!/usr/bin/env bash
# Installs the built workspace (catkin_make install, into the workspace's install/) and checks it as
# a user of the install space would, in an environment with nothing of the devel space: after
# sourcing install/setup.bash, `sift_hull --help`, `sift_hull_bench --help` and
# `sift_hull_ros --help` run from PATH and through rosrun, roslaunch finds the launch files with
# their parameter files, and the nodelets are registered. One JUnit case per check in RESULTS_DIR
# (install-*.xml).
#
#   scripts/install_check.sh RESULTS_DIR
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
source "$here/common.sh"
results="$(realpath -m "${1:?usage: scripts/install_check.sh RESULTS_DIR}")"
mkdir -p "$results"
junit=(/usr/bin/python3 "$here/junit.py")
log="$workspace/install.log"

record() {  # NAME LOG COMMAND...: one case, passed when COMMAND succeeds
  local name="$1" case_log="$2"
  shift 2
  if "$@" >"$case_log" 2>&1; then
    "${junit[@]}" case "$results/install-$name.xml" install "$name"
  else
    "${junit[@]}" case "$results/install-$name.xml" install "$name" \
      --failure "install check '$name' failed" --log "$case_log" --tail 30
    echo "install check '$name' failed (log: $case_log)"
  fi
}

record catkin_make_install "$log" bash "$here/build.sh" install
in_install() {  # COMMAND: run in a clean environment with only the install space sourced
  env -i HOME="$HOME" PATH=/usr/bin:/bin bash -c \
    "source '$workspace/install/setup.bash' && $1"
}
record sift_hull_help "$workspace/install_help.log" in_install \
  'sift_hull --help | grep -q "^usage: sift_hull <command>" && sift_hull_bench --help | grep -q "^usage: sift_hull_bench <command>" && sift_hull_ros --help | grep -q "^usage: sift_hull_ros"'
record rosrun "$workspace/install_rosrun.log" in_install \
  'rosrun sift_hull sift_hull --help | grep -q "^usage: sift_hull" && rosrun sift_hull sift_hull_bench --help | grep -q "^usage: sift_hull_bench" && [[ "$(rospack find sift_hull)" == */install/share/sift_hull ]]'
record roslaunch "$workspace/install_roslaunch.log" in_install \
  'for f in hull matcher; do roslaunch --dump-params sift_hull $f.launch | grep -q "/queue_size"; done && roslaunch --files sift_hull demo.launch bag:=x.bag | grep -q install/share/sift_hull/launch/hull.launch && [[ -f "$(rospack find sift_hull)/config/sift_hull.rviz" ]]'
record nodelets "$workspace/install_nodelets.log" in_install \
  'rospack plugins --attrib=plugin nodelet | grep -q "^sift_hull .*install/share/sift_hull/nodelet_plugins.xml"'
