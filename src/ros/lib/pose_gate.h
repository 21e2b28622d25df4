#pragma once

#include <message_filters/simple_filter.h>
#include <sensor_msgs/Image.h>

#include <functional>

#include "lib/pose_waits.h"

namespace sift_hull {

/// Between the tf filter and the camera_info synchroniser: passes on the silhouettes whose pose
/// came within the timeout (PoseWaits), and hands the others to `on_late`.
class PoseGate : public message_filters::SimpleFilter<sensor_msgs::Image> {
 public:
  PoseGate(PoseWaits* waits, std::function<void(const sensor_msgs::ImageConstPtr&)> on_late)
      : waits_(waits), on_late_(std::move(on_late)) {}

  template <class Filter>
  void connectInput(Filter& input) {
    connection_ = input.registerCallback(&PoseGate::add, this);
  }

 private:
  void add(const sensor_msgs::ImageConstPtr& silhouette) {
    if (waits_->posed(silhouette->header.frame_id, silhouette->header.stamp.toSec())) {
      signalMessage(silhouette);
    } else {
      on_late_(silhouette);
    }
  }

  PoseWaits* waits_;
  std::function<void(const sensor_msgs::ImageConstPtr&)> on_late_;
  message_filters::Connection connection_;
};

}  // namespace sift_hull
