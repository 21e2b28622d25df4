#include "lib/pose_wait.h"

#include <tf2_eigen/tf2_eigen.h>

#include <sstream>

namespace sift_hull {
namespace {

std::string shortNumber(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

const char* failureText(tf2_ros::filter_failure_reasons::FilterFailureReason reason) {
  switch (reason) {
    case tf2_ros::filter_failure_reasons::EmptyFrameID:
      return "empty frame id";
    case tf2_ros::filter_failure_reasons::OutTheBack:
      return "older than the transforms tf keeps";
    default:
      return "the transform never arrived";
  }
}

}  // namespace

PoseWait::PoseWait(ros::NodeHandle nh, tf2_ros::Buffer* tf, std::string world_frame,
                   uint32_t queue_size, double timeout_s, Posed posed, Dropped dropped)
    : tf_(tf),
      world_frame_(std::move(world_frame)),
      timeout_s_(timeout_s),
      posed_(std::move(posed)),
      dropped_view_(std::move(dropped)),
      waits_(timeout_s, 4 * static_cast<size_t>(queue_size)),
      filter_(*tf, world_frame_, queue_size, nh) {
  filter_.setTolerance(ros::Duration(0.0));
  filter_.registerCallback(&PoseWait::onPose, this);
  filter_.registerFailureCallback(
      [this](const sensor_msgs::ImageConstPtr& image,
             tf2_ros::filter_failure_reasons::FilterFailureReason reason) {
        onFailure(image, reason);
      });
  timer_ =
      nh.createWallTimer(ros::WallDuration(0.2), [this](const ros::WallTimerEvent&) { expire(); });
}

void PoseWait::add(const sensor_msgs::ImageConstPtr& image,
                   const sensor_msgs::CameraInfoConstPtr& info) {
  const std::string& frame = image->header.frame_id;
  if (!waits_.arrived(frame, image->header.stamp.toSec(), PoseWaits::Clock::now())) {
    ++dropped_;
    const std::string why = "a second view of '" + frame +
                            "' with the stamp of one waiting for its pose (one view per frame id "
                            "and stamp)";
    dropped_view_(frame, why);
    return;
  }
  {
    std::lock_guard<std::mutex> lock(infos_mutex_);
    infos_[image.get()] = info;
  }
  filter_.add(image);  // no lock held: the filter may drop an older image (onFailure) here
}

size_t PoseWait::clear() {
  {
    // Without its camera_info an image the filter still passes on is ignored (onPose).
    std::lock_guard<std::mutex> lock(infos_mutex_);
    infos_.clear();
  }
  filter_.clear();
  return waits_.clear();
}

sensor_msgs::CameraInfoConstPtr PoseWait::takeInfo(const sensor_msgs::Image* image) {
  std::lock_guard<std::mutex> lock(infos_mutex_);
  const auto found = infos_.find(image);
  if (found == infos_.end()) return nullptr;
  sensor_msgs::CameraInfoConstPtr info = found->second;
  infos_.erase(found);
  return info;
}

void PoseWait::onPose(const sensor_msgs::ImageConstPtr& image) {
  const sensor_msgs::CameraInfoConstPtr info = takeInfo(image.get());
  const std::string& frame = image->header.frame_id;
  if (!info) return;
  if (!waits_.posed(frame, image->header.stamp.toSec())) {
    // Counted when it expired.
    dropped_view_(frame, "the pose of '" + frame + "' came after ~pose_timeout_s");
    return;
  }
  Eigen::Isometry3d T_W_C;
  try {
    T_W_C = tf2::transformToEigen(tf_->lookupTransform(world_frame_, frame, image->header.stamp));
  } catch (const tf2::TransformException& e) {  // the filter said it can: rare, but say so
    ++dropped_;
    dropped_view_(frame, e.what());
    return;
  }
  posed_(image, info, T_W_C);
}

void PoseWait::onFailure(const sensor_msgs::ImageConstPtr& image,
                         tf2_ros::filter_failure_reasons::FilterFailureReason reason) {
  takeInfo(image.get());
  const std::string& frame = image->header.frame_id;
  if (waits_.forget(frame, image->header.stamp.toSec())) ++dropped_;
  dropped_view_(
      frame, "no pose of '" + frame + "' in '" + world_frame_ + "' (" + failureText(reason) + ")");
}

void PoseWait::expire() {
  for (const std::string& frame : waits_.expire(PoseWaits::Clock::now())) {
    ++dropped_;
    dropped_view_(frame, "no pose of '" + frame + "' in '" + world_frame_ + "' within " +
                             shortNumber(timeout_s_) + " s (~pose_timeout_s)");
  }
}

}  // namespace sift_hull
