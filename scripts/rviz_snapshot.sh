#!/usr/bin/env bash
# The demo with rviz (config/sift_hull.rviz) on a virtual X display: plays the synthetic scene's
# bag through both nodes and, once the last view is in, saves a PNG of the rviz window showing the
# hull, the camera frames, the last silhouette and the matches image. Output: demo_output/ (or $1),
# the picture at rviz.png there. Further arguments go to demo.launch: photo_carve:=true shows the
# photo-carved hull's coloured cells (config/sift_hull_photo.rviz), after its first pass.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
source "$here/common.sh"
out="$(realpath -m "${1:-$repo_root/demo_output}")"
shift || true

prepare_demo "$out"

# Xvfb picks a free display and writes its number once it accepts clients.
rm -f "$out/xvfb.display"
Xvfb -displayfd 3 -screen 0 1280x800x24 -nolisten tcp 3>"$out/xvfb.display" >"$out/xvfb.log" 2>&1 &
xvfb=$!
for _ in $(seq 100); do
  [[ -s "$out/xvfb.display" ]] && break
  sleep 0.1
done
[[ -s "$out/xvfb.display" ]] || { cat "$out/xvfb.log" >&2; echo "Xvfb did not start" >&2; exit 1; }
display=":$(head -n 1 "$out/xvfb.display")"
launch=""
cleanup() {
  # The launch runs under timeout in a subshell; timeout passes the interrupt on to roslaunch.
  if [[ -n "$launch" ]]; then
    pkill -INT -P "$launch" 2>/dev/null || true
    wait "$launch" 2>/dev/null || true
  fi
  kill "$xvfb" 2>/dev/null || true
}
trap cleanup EXIT

echo "playing $out/scene.bag through both nodes with rviz on display $display ..."
rm -rf "$out/nodes"  # its summary.json is the signal below, so none may be left from before
DISPLAY="$display" run_demo_launch "$out" rviz:=true "$@" >"$out/launch.log" 2>&1 &
launch=$!
# With rviz open the launch stays up after saving; the summary tells that the last view is in.
for _ in $(seq 300); do
  [[ -s "$out/nodes/summary.json" ]] && break
  kill -0 "$launch" 2>/dev/null || { tail -n 30 "$out/launch.log"; exit 1; }
  sleep 1
done
[[ -s "$out/nodes/summary.json" ]] || { echo "no summary after 300 s" >&2; exit 1; }
sleep "${SIFT_HULL_RVIZ_SETTLE_S:-5}"  # rviz draws the latched hull and mesh
if [[ " $* " == *" photo_carve:=true "* ]]; then
  # and the photo carving's pass with every view, once it is carved in (the hull's /diagnostics)
  set +u
  source "$workspace/devel/setup.bash"
  set -u
  for _ in $(seq 60); do
    timeout 10 /usr/bin/python3 - <<'PY' && break  # ROS's python3, whatever PATH says
import sys, rospy
from diagnostic_msgs.msg import DiagnosticArray
rospy.init_node("rviz_snapshot_wait", anonymous=True)
while not rospy.is_shutdown():
    for status in rospy.wait_for_message("/diagnostics", DiagnosticArray, timeout=5).status:
        values = {v.key: v.value for v in status.values}
        if status.name == "hull: hull" and "photo pass running" in values:
            done = (values["photo pass running"] == "no" and
                    values["photo views of the last pass applied"] == values["photo views kept"])
            sys.exit(0 if done else 1)
PY
    sleep 2
  done
  sleep 5  # rviz draws the coloured cloud
fi
import -display "$display" -window root "$out/rviz.png"
echo "rviz snapshot: $out/rviz.png"
