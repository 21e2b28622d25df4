# Sourced by the other scripts: paths and an environment in which catkin runs Debian's Python.
repo_root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
workspace="$(realpath -m "${SIFT_HULL_WORKSPACE:-$repo_root/.catkin_ws}")"
# catkin and ROS message generation import catkin_pkg, genmsg and friends, which Debian installs
# for /usr/bin/python3 only; a pyenv or virtualenv python3 earlier on PATH cannot import them.
export PATH="/usr/bin:/bin:$PATH"
unset PYTHONHOME PYTHONPATH VIRTUAL_ENV
export PYENV_VERSION=system
mkdir -p "$workspace"

# Used by demo.sh and rviz_snapshot.sh: installs, builds ($sift_hull is the program), renders the
# synthetic scene into $1/scene and writes its bag $1/scene.bag.
prepare_demo() {
  local out="$1"
  bash "$repo_root/scripts/setup.sh"
  echo "building (log: $workspace/build.log) ..."
  if ! sift_hull="$(bash "$repo_root/scripts/build.sh" 2>"$workspace/build.log" | tail -n 1)" ||
    [[ ! -x "$sift_hull" ]]; then
    tail -n 30 "$workspace/build.log" >&2
    echo "the build failed; log: $workspace/build.log" >&2
    return 1
  fi
  mkdir -p "$out"
  echo "rendering the synthetic scene ..."
  "$sift_hull" scene --out "$out/scene" --views 16 --size 640x480
  local info=(dataset-info --calib "$out/scene/scene_par.txt" --silhouettes "$out/scene/masks")
  "$sift_hull" "${info[@]}" --json >"$out/scene_info.json"
  "$sift_hull" "${info[@]}" | tail -n 1
  "$(dirname "$sift_hull")/sift_hull_ros" bag --calib "$out/scene/scene_par.txt" --images "$out/scene" \
    --silhouettes "$out/scene/masks" --out "$out/scene.bag" --rate 4
}

# Runs demo.launch on $1/scene.bag, saving into $1/nodes; more roslaunch arguments may follow.
# Without a running ROS master, roslaunch starts one. Gives up after 5 minutes.
run_demo_launch() {
  local out="$1"
  shift
  set +u
  source "$workspace/devel/setup.bash"
  set -u
  rm -rf "$out/nodes"
  timeout 300 roslaunch sift_hull demo.launch bag:="$out/scene.bag" out:="$out/nodes" "$@"
}
