// save_results: waits until the hull and matcher nodes have processed every view of a bag being
// played, saves what they made of it into ~out_dir, and exits (0 when everything arrived). With
// ~end_launch, a complete save ends the roslaunch that started it, as Ctrl-C would.

#include <ros/network.h>
#include <ros/ros.h>
#include <signal.h>
#include <unistd.h>
#include <xmlrpcpp/XmlRpcClient.h>

#include <string>

#include "lib/result_saver.h"
#include "lib/ros_params.h"
#include "lib/wall_wait.h"

namespace {

/// Wall time roslaunch gets to stop this node once asked to end.
constexpr double kLaunchEndWait_s = 30.0;

/// Whether the roslaunch serving XML-RPC at `uri` has the process id `pid`.
bool roslaunchHasPid(const std::string& uri, pid_t pid) {
  std::string host;
  uint32_t port = 0;
  if (!ros::network::splitURI(uri, host, port)) return false;
  XmlRpc::XmlRpcClient client(host.c_str(), static_cast<int>(port), "/");
  XmlRpc::XmlRpcValue none, answer;  // get_pid answers [code, message, pid]
  if (!client.execute("get_pid", none, answer) || client.isFault()) return false;
  return answer.getType() == XmlRpc::XmlRpcValue::TypeArray && answer.size() == 3 &&
         answer[2].getType() == XmlRpc::XmlRpcValue::TypeInt && static_cast<int>(answer[2]) == pid;
}

/// Whether this process was started by a roslaunch of this master (one of /roslaunch/uris), rather
/// than by rosrun or a shell.
bool startedByRoslaunch() {
  XmlRpc::XmlRpcValue uris;
  if (!ros::param::get("/roslaunch/uris", uris) ||
      uris.getType() != XmlRpc::XmlRpcValue::TypeStruct) {
    return false;
  }
  for (auto& entry : uris) {
    if (entry.second.getType() != XmlRpc::XmlRpcValue::TypeString) continue;
    if (roslaunchHasPid(static_cast<std::string>(entry.second), getppid())) return true;
  }
  return false;
}

/// Ends the launch as Ctrl-C does: SIGINT to roslaunch, which stops every node, this one too,
/// and ends without a required node's death. Waits for that stop. False when no roslaunch
/// started this node.
bool endLaunch() {
  if (!startedByRoslaunch() || kill(getppid(), SIGINT) != 0) return false;
  sift_hull::waitOnWallClock([] { return !ros::ok(); }, kLaunchEndWait_s, 0.05);
  return true;
}

/// Waits for the bag's last view and pair, saves, and ends the launch when asked to; the exit code.
int waitAndSave(const sift_hull::ResultSaverConfig& config) {
  ros::NodeHandle nh;
  sift_hull::ResultSaver saver(nh, config, sift_hull::readBagEnd(config.bag));
  sift_hull::waitOnWallClock([&] { return saver.complete(); }, config.timeout_s, 0.05,
                             [] { ros::spinOnce(); });
  if (!ros::ok()) return 1;
  if (!saver.complete()) {
    ROS_ERROR(
        "save_results: the bag's last view or pair did not come through in %.0f s; "
        "saving what there is",
        config.timeout_s);
  }
  const nlohmann::json summary = saver.save();
  const bool complete = summary["complete"].get<bool>();
  ROS_INFO("save_results: wrote %s/summary.json", config.out_dir.c_str());
  if (complete && config.end_launch) {
    ROS_INFO("save_results: every view and pair is in; ending the launch");
    if (!endLaunch()) ROS_WARN("save_results: no roslaunch started this node; nothing to end");
  }
  return complete ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "save_results");
  ros::NodeHandle nh, private_nh("~");
  try {
    return waitAndSave(sift_hull::ros_params::readResultSaverConfig(private_nh));
  } catch (const std::exception& e) {
    ROS_FATAL("save_results: %s", e.what());
    return 1;
  }
}
