// The matcher node's calibrated inputs: a stereo pair's cameras (from camera_info and tf) and one
// moving camera's frames (poses from tf, a keyframe), on the worker and the callbacks as marked in
// matcher_node.h.

#include <tf2_eigen/tf2_eigen.h>

#include <cmath>
#include <sstream>
#include <utility>

#include "lib/conversions.h"
#include "nodes/matcher_node.h"

namespace sift_hull {
namespace {

/// Two cameras from their camera_infos, the left at the origin of its own frame and the right at
/// T_L_R in it.
bool camerasFromInfos(const sensor_msgs::CameraInfo& left_info,
                      const sensor_msgs::CameraInfo& right_info, const cv::Size& left_size,
                      const cv::Size& right_size, const Eigen::Isometry3d& T_L_R, bool rectified,
                      PinholeCamera* left, PinholeCamera* right, std::string* why_not) {
  return ros_conversions::cameraFromInfo(left_info, Eigen::Isometry3d::Identity(), left_size, left,
                                         why_not, rectified) &&
         ros_conversions::cameraFromInfo(right_info, T_L_R, right_size, right, why_not, rectified);
}

constexpr double kRadiansPerDegree = M_PI / 180.0;

}  // namespace

void MatcherNode::onCalibratedPair(const sensor_msgs::ImageConstPtr& left,
                                   const sensor_msgs::ImageConstPtr& right,
                                   const sensor_msgs::CameraInfoConstPtr& left_info,
                                   const sensor_msgs::CameraInfoConstPtr& right_info) {
  pairing_.paired();
  enqueue({left, right, left_info, right_info});
}

bool MatcherNode::rightPoseFromTf(const Image& left, const Image& right, Eigen::Isometry3d* T_L_R) {
  try {
    waitForTransform(left.header.frame_id, right.header.frame_id, left.header.stamp);
    *T_L_R = tf2::transformToEigen(
        tf_buffer_.lookupTransform(left.header.frame_id, right.header.frame_id, left.header.stamp));
  } catch (const tf2::TransformException& e) {
    log_.error("matcher: pair ignored: ", e.what());
    return false;
  }
  return true;
}

void MatcherNode::onCalibratedFrame(const sensor_msgs::ImageConstPtr& frame,
                                    const sensor_msgs::CameraInfoConstPtr& info) {
  pairing_.paired();
  const std::string why_not = unusableFrame(*frame, *info);
  {
    std::lock_guard<std::mutex> lock(keyframe_mutex_);
    ++frame_counts_.received;
    // Refused before it can become the keyframe, which would waste the next good frame.
    if (!why_not.empty()) ++frame_counts_.unusable;
  }
  if (!why_not.empty()) {
    log_.error("matcher: frame ignored: ", why_not);
    return;
  }
  pose_wait_->add(frame, info);  // no lock held: the pose may come at once (onPosedFrame)
}

std::string MatcherNode::unusableFrame(const Image& frame, const Info& info) const {
  std::string why_not;
  PinholeCamera camera;
  if (!ros_conversions::withinPixelLimit(frame, pipeline()->settings.sift.max_image_pixels,
                                         &why_not) ||
      !ros_conversions::holdsEightBitImage(frame, &why_not) ||
      !ros_conversions::cameraFromInfo(info, Eigen::Isometry3d::Identity(),
                                       cv::Size(frame.width, frame.height), &camera, &why_not,
                                       settings_.node.rectified)) {
    return why_not;
  }
  // A frame stamped ahead of the node's clock would hold the keyframe until then (later frames
  // are matched only when stamped after it). Not checked before the clock starts (a bag's).
  const ros::Time now = ros::Time::now();
  if (!now.isZero() && frame.header.stamp.toSec() > now.toSec() + kMaxFrameAhead_s) {
    std::ostringstream why;  // no value in it: one throttled message however far ahead
    why << "stamped more than " << kMaxFrameAhead_s
        << " s after this node's clock: are the clocks synchronised?";
    return why.str();
  }
  return "";
}

void MatcherNode::onPosedFrame(const sensor_msgs::ImageConstPtr& frame,
                               const sensor_msgs::CameraInfoConstPtr& info,
                               const Eigen::Isometry3d& T_W_C) {
  Pair pair;
  {
    std::lock_guard<std::mutex> lock(keyframe_mutex_);
    if (!keyframe_.image) {
      ++frame_counts_.keyframes;
      keyframe_ = Keyframe{frame, info, T_W_C};
      return;
    }
    if (frame->header.stamp <= keyframe_.image->header.stamp) {
      ++frame_counts_.out_of_order;
      log_.error("matcher: frame ignored: ", "its stamp is not after the keyframe's");
      return;
    }
    // The frame's camera in the keyframe camera's frame.
    const Eigen::Isometry3d T_K_C = keyframe_.T_W_C.inverse() * T_W_C;
    const double baseline_m = T_K_C.translation().norm();
    const double rotation_deg = Eigen::AngleAxisd(T_K_C.rotation()).angle() / kRadiansPerDegree;
    if (!std::isfinite(baseline_m) || !std::isfinite(rotation_deg)) {
      ++frame_counts_.unusable;
      log_.error("matcher: frame ignored: ", "its pose in tf is not finite");
      return;
    }
    if (rotation_deg > settings_.node.max_rotation_deg) {
      ++frame_counts_.turned;
      keyframe_ = Keyframe{frame, info, T_W_C};
      return;
    }
    if (baseline_m <= settings_.node.min_baseline_m) {
      ++frame_counts_.skipped;
      return;
    }
    ++frame_counts_.paired;
    pair = Pair{keyframe_.image, frame, keyframe_.info, info, true, T_K_C};
    keyframe_ = Keyframe{frame, info, T_W_C};
  }
  enqueue(std::move(pair));  // the keyframe is the left image, as frame to frame uncalibrated
}

bool MatcherNode::posedCameras(const Image& left, const Image& right, const Info& left_info,
                               const Info& right_info, const Eigen::Isometry3d& T_L_R,
                               StereoCameras* cameras) {
  std::string why_not;
  if (!camerasFromInfos(left_info, right_info, cv::Size(left.width, left.height),
                        cv::Size(right.width, right.height), T_L_R, settings_.node.rectified,
                        &cameras->left, &cameras->right, &why_not)) {
    log_.error("matcher: pair ignored: ", why_not);
    return false;
  }
  return true;
}

bool MatcherNode::stereoCameras(const Image& left, const Image& right, const Info& left_info,
                                const Info& right_info, StereoCameras* cameras) {
  const bool rectified = settings_.node.rectified;
  const cv::Size left_size(left.width, left.height), right_size(right.width, right.height);
  std::string why_not;
  bool ok = false;
  if (left.header.frame_id == right.header.frame_id) {
    // One frame for both (stereo_image_proc): tf would say identity; the baseline is in P.
    ok = ros_conversions::sharedFrameStereo(left_info, right_info, left_size, right_size, rectified,
                                            &cameras->left, &cameras->right, &why_not);
  } else {
    Eigen::Isometry3d T_L_R;
    if (!rightPoseFromTf(left, right, &T_L_R)) return false;
    ok = camerasFromInfos(left_info, right_info, left_size, right_size, T_L_R, rectified,
                          &cameras->left, &cameras->right, &why_not);
  }
  if (!ok) {
    log_.error("matcher: pair ignored: ", why_not);
    return false;
  }
  const double baseline_m = (cameras->right.centre() - cameras->left.centre()).norm();
  if (!(baseline_m > 1e-9)) {
    log_.error("matcher: pair ignored: ",
               "the cameras have no baseline (frames '" + left.header.frame_id + "' and '" +
                   right.header.frame_id +
                   "'): with one frame for both, the right camera_info's P[0,3] must be "
                   "-fx * baseline; with two, tf must place them apart");
    return false;
  }
  return true;
}

}  // namespace sift_hull
