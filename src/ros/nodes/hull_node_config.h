#pragma once

// hull_node's own settings, without ROS, and the table its parameters derive from.

#include <string>

#include "sift_hull/hull/hull_stream.h"
#include "sift_hull/hull/silhouette.h"
#include "sift_hull/mvs/photo_stream.h"
#include "sift_hull/refine/point_carved_stream.h"
#include "sift_hull/settings.h"

namespace sift_hull {

/// Node settings besides the hull's own (HullStreamConfig).
struct HullNodeConfig {
  std::string world_frame = "world";
  /// Silhouettes waiting for their camera_info (when more wait, the oldest is dropped, and
  /// /diagnostics warns of inputs that do not pair), paired ones waiting for their pose (the oldest
  /// dropped with an error, counted as without pose), and views waiting to be carved (the oldest
  /// dropped and counted in /diagnostics).
  int queue_size = 10;
  /// A silhouette whose pose is not in tf this long after it paired with its camera_info is
  /// reported and, should the pose come later still, not carved. <= 0: wait as long as the queue
  /// allows.
  double pose_timeout_s = 5.0;
  /// Subscribe `image` (8-bit colour or mono) instead of `silhouette`, and extract each
  /// silhouette by `recipe` (SilhouetteConfig: its method, threshold, dilation and erosion).
  bool from_image = false;
  /// The silhouettes are of rectified images (image_proc's image_rect, whose camera_info is the
  /// raw image's): cameras from P and R, whatever D says. False: raw, K and D, unless D is zero
  /// and R and P rectify (ros_conversions::cameraInfoGeometry).
  bool rectified = false;
  SilhouetteConfig recipe;
  /// Seconds of wall time between /diagnostics reports (diagnostic_updater's own parameter).
  double diagnostic_period = 1.0;
  /// Wall time between refinements with newly arrived surface points, seconds: each one derives
  /// the free voxels of every point kept anew.
  double refine_period_s = 1.0;
  /// Free-space carving with the surface points (`surface_points`): how many are kept, which.
  PointCarvingConfig carving;
  /// Photo carving (PhotoStream): the photographs are taken with the silhouettes (`image`, paired
  /// by stamp with the silhouette and its camera_info; with from_image the images themselves),
  /// passes of dense depth carve the hull in the background, and the clouds of occupied centres
  /// carry the photographs' colours.
  bool photo_carve = false;
  /// With photo_carve: octomap_full is OctoMap's ColorOcTree (octomap_server's colour mode).
  bool photo_color_octomap = false;
  /// The passes' settings (photo_max_views and PhotoCarveConfig's).
  PhotoStreamConfig photo;
};

/// Its settings (sift_hull/settings.h); the silhouette recipe and the carving settings are nested
/// without a prefix.
template <>
const SettingTable<HullNodeConfig>& settingsOf<HullNodeConfig>();

/// Everything hull_node is configured with: its private parameters are the settings of both
/// tables, node first.
struct HullNodeSettings {
  HullNodeConfig node;
  HullStreamConfig stream;
};

template <>
const SettingTable<HullNodeSettings>& settingsOf<HullNodeSettings>();

}  // namespace sift_hull
