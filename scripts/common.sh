# Sourced by the other scripts: paths and an environment in which catkin runs Debian's Python.
repo_root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
workspace="$(realpath -m "${SIFT_HULL_WORKSPACE:-$repo_root/.catkin_ws}")"
# catkin and ROS message generation import catkin_pkg, genmsg and friends, which Debian installs
# for /usr/bin/python3 only; a pyenv or virtualenv python3 earlier on PATH cannot import them.
export PATH="/usr/bin:/bin:$PATH"
unset PYTHONHOME PYTHONPATH VIRTUAL_ENV
export PYENV_VERSION=system
mkdir -p "$workspace"
