#include "ros_params.h"

#include <stdexcept>

namespace sift_hull {
namespace ros_params {

HullConfig readHullConfig(const ros::NodeHandle& private_nh) {
  HullConfig config;
  private_nh.param("depth", config.max_depth, config.max_depth);
  private_nh.param("carve_outside_image", config.carve_outside_image, config.carve_outside_image);
  private_nh.param("slack_px", config.distance_slack_px, config.distance_slack_px);
  private_nh.param("threads", config.threads, config.threads);
  validate(config);
  return config;
}

HullStreamConfig readHullStreamConfig(const ros::NodeHandle& private_nh) {
  HullStreamConfig config;
  config.hull = readHullConfig(private_nh);
  std::vector<double> box;
  private_nh.param("box", box, box);
  if (!box.empty()) {
    if (box.size() != 6) throw std::invalid_argument("~box must hold six numbers or none");
    Box3d given;
    given.min_W = Eigen::Vector3d(box[0], box[1], box[2]);
    given.max_W = Eigen::Vector3d(box[3], box[4], box[5]);
    if (!(given.size().array() > 0.0).all()) {
      throw std::invalid_argument("~box: each max must exceed its min");
    }
    config.box = given;
  }
  private_nh.param("skip_views", config.skip_views, config.skip_views);
  return config;
}

}  // namespace ros_params
}  // namespace sift_hull
