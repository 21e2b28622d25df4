#pragma once

// matcher_node's own settings, without ROS, and the table its parameters derive from.

#include <string>
#include <vector>

#include "sift_hull/features/matching.h"
#include "sift_hull/features/sift.h"
#include "sift_hull/filters/filter.h"
#include "sift_hull/settings.h"

namespace sift_hull {

/// Node settings besides the matching's own (SiftConfig, MatchConfig, FilterConfigs).
struct MatcherNodeConfig {
  /// Filters to run, by makeFilter name ("gsc", "magsac", "epipolar+gsc", ...). The epipolar
  /// filter needs `calibrated`.
  std::vector<std::string> filters = {kDefaultFilter};
  int queue_size = 10;  ///< images waiting for their partner
  /// Paired images waiting for a worker; when more come, the oldest pair is dropped (counted in
  /// /diagnostics), so a stream faster than matching costs neither memory nor latency.
  int max_waiting_pairs = 2;
  /// Threads matching pairs side by side; with more than one, correspondences of pairs close in
  /// time may be published out of stamp order.
  int workers = 2;
  bool approximate_sync = false;  ///< pair images by nearest stamps instead of equal ones
  /// Also take the camera_info beside each image (image_transport's convention: the image topic's
  /// namespace + camera_info, so left/camera_info and right/camera_info follow remappings of
  /// left/image and right/image; paired by equal stamps with the images) and the right camera's
  /// pose relative to the left: from tf when the images' frames differ, from the right P's
  /// baseline when they share one frame (stereo_image_proc's convention). Gives the epipolar
  /// filter's F, and the `points` of the matches the first filter keeps.
  bool calibrated = false;
  /// The images are rectified (image_proc's image_rect, whose camera_info is the raw image's):
  /// their cameras are camera_info's P and R, whatever D says. Without it, D all zero with an R or
  /// P that rectifies counts as rectified too (ros_conversions::cameraInfoGeometry).
  bool rectified = false;
  /// Subscribe one `image` topic instead, and match each frame with the one before it (the
  /// earlier frame is the left image). With `calibrated` too: the camera_info beside `image`,
  /// each frame's camera pose in `world_frame` from tf, and a keyframe matched with the first
  /// later frame whose camera centre is more than `min_baseline_m` from the keyframe's.
  bool frame_to_frame = false;
  /// Calibrated frame to frame: the frame the camera poses are looked up in.
  std::string world_frame = "world";
  /// Calibrated frame to frame: a frame whose pose is not in tf within this much wall time is
  /// dropped (counted in /diagnostics); <= 0: no limit.
  double pose_timeout_s = 5.0;
  /// Calibrated frame to frame: frames whose camera centre is this close to the keyframe's are
  /// skipped (counted); the first one further away is matched with the keyframe and becomes it.
  double min_baseline_m = 0.05;
  /// Calibrated frame to frame: a frame turned further than this from the keyframe is not matched
  /// (the views differ too much); it becomes the keyframe (counted).
  double max_rotation_deg = 30.0;
  /// How the images arrive: "raw", "compressed" (decoded here when no plugin provides it), or
  /// another installed image_transport plugin.
  std::string image_transport = "raw";
  /// Seconds of wall time between /diagnostics reports (diagnostic_updater's own parameter).
  double diagnostic_period = 1.0;
};

template <>
const SettingTable<MatcherNodeConfig>& settingsOf<MatcherNodeConfig>();

/// Everything the matcher node is configured with.
struct MatcherSettings {
  MatcherNodeConfig node;
  SiftConfig sift;
  MatchConfig matching;
  FilterConfigs filters;
};

/// Its settings: the node's, SIFT's, the matching's and the filters' (each filter's composed with
/// its name: lsc_max_relative_error).
template <>
const SettingTable<MatcherSettings>& settingsOf<MatcherSettings>();

}  // namespace sift_hull
