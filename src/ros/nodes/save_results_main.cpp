// save_results: waits until the hull and matcher nodes have processed every view of a bag being
// played, saves what they made of it into ~out_dir, and exits (0 when everything arrived).

#include <ros/ros.h>

#include "lib/result_saver.h"
#include "lib/ros_params.h"
#include "lib/wall_wait.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "save_results");
  ros::NodeHandle nh, private_nh("~");
  try {
    const sift_hull::ResultSaverConfig config =
        sift_hull::ros_params::readResultSaverConfig(private_nh);
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
    ROS_INFO("save_results: wrote %s/summary.json", config.out_dir.c_str());
    return summary["complete"].get<bool>() ? 0 : 1;
  } catch (const std::exception& e) {
    ROS_FATAL("save_results: %s", e.what());
    return 1;
  }
}
