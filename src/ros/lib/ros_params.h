#pragma once

// One reader per config struct; every fallback is the struct's own default. A parameter that is
// set with the wrong type (a string where a list is expected, 2.5 for an integer) is an error
// (std::invalid_argument), not a silent default.
//
// A parameter's name is its config field's name (config/hull.yaml and config/matcher.yaml state
// every one). The one exception is RobustFitConfig, held twice in FilterConfigs: its fields are
// ~ransac_<field> and ~magsac_<field>. Renamed parameters are still read under their old names,
// with a deprecation warning naming the new one; when both are set, the new name wins.
// octomap_server's names for the hull node's settings are understood too: ~frame_id as
// ~world_frame, and ~resolution refused with the setting to use instead (~max_depth).

#include <ros/node_handle.h>

#include <set>
#include <string>
#include <vector>

#include "lib/result_saver.h"
#include "nodes/hull_node.h"
#include "nodes/matcher_node.h"
#include "sift_hull/filters/filter.h"
#include "sift_hull/hull/hull_config.h"
#include "sift_hull/hull/hull_stream.h"
#include "sift_hull/hull/silhouette.h"
#include "sift_hull/io/calibration.h"
#include "sift_hull/refine/free_space.h"
#include "sift_hull/refine/surface_points.h"

namespace sift_hull {
namespace ros_params {

/// ~max_descriptor_distance, and its dynamic_reconfigure setting, write "no limit" as 0;
/// MatchConfig writes it as infinity.
double descriptorDistanceFromParam(double param);
double descriptorDistanceParam(double distance);

/// ~threshold (grey level in [0, 1]), ~dilate_px, ~erode_px: the Middlebury silhouette recipe.
SilhouetteConfig readSilhouetteConfig(const ros::NodeHandle& private_nh);

/// ~max_depth, ~carve_outside_image, ~distance_slack_px, ~threads, ~distance_reduction.
/// Deprecated: ~depth (~max_depth), ~slack_px (~distance_slack_px). octomap_server's ~resolution
/// is refused (std::invalid_argument naming ~max_depth): the voxel edge follows from the box and
/// ~max_depth.
HullConfig readHullConfig(const ros::NodeHandle& private_nh);

/// The hull config, ~box ([xmin, ymin, zmin, xmax, ymax, zmax] in the world frame, metres; empty
/// or absent: automatic), ~skip_views (frame ids of silhouettes to leave out),
/// ~min_view_distance_m, ~min_view_angle_deg, ~max_waiting_views and ~max_views. Throws
/// std::invalid_argument for a box that is not six numbers with max > min, or a negative view
/// separation.
HullStreamConfig readHullStreamConfig(const ros::NodeHandle& private_nh);

/// ~max_features, ~octave_layers, ~contrast_threshold, ~edge_threshold, ~sigma_px,
/// ~max_image_pixels.
SiftConfig readSiftConfig(const ros::NodeHandle& private_nh);

/// ~ratio, ~max_descriptor_distance (<= 0: none), ~cross_check, ~backend.
/// Deprecated: ~matcher (~backend).
MatchConfig readMatchConfig(const ros::NodeHandle& private_nh);

/// ~max_epipolar_px.
EpipolarConfig readEpipolarConfig(const ros::NodeHandle& private_nh);

/// ~max_histogram_distance, ~threads, ~max_support.
/// Deprecated: ~gsc_max_histogram_distance, ~gsc_threads.
GscConfig readGscConfig(const ros::NodeHandle& private_nh);

/// ~<prefix>_max_epipolar_px, ~<prefix>_confidence, ~<prefix>_max_iterations, ~<prefix>_seed,
/// prefix "ransac" or
/// "magsac" (the FilterConfigs member). Deprecated: ~robust_confidence and ~robust_max_iterations,
/// which set both instances unless the instance's own name is set.
RobustFitConfig readRobustFitConfig(const ros::NodeHandle& private_nh, const std::string& prefix);

/// ~grid_cells, ~threshold_factor, ~with_rotation, ~with_scale.
/// Deprecated: ~gms_grid_cells, ~gms_threshold_factor, ~gms_with_rotation, ~gms_with_scale.
GmsConfig readGmsConfig(const ros::NodeHandle& private_nh);

/// ~lsc_neighbours, ~lsc_max_relative_error, ~lsc_min_tolerance_px, ~lsc_min_support.
LscConfig readLscConfig(const ros::NodeHandle& private_nh);

/// ~local_gsc_neighbours, ~local_gsc_max_histogram_distance.
LocalGscConfig readLocalGscConfig(const ros::NodeHandle& private_nh);

/// ~guided_max_transfer_px, ~guided_homography_share, ~guided_max_models,
/// ~guided_min_model_inliers, ~guided_min_support, ~guided_max_fit_points.
GuidedConfig readGuidedConfig(const ros::NodeHandle& private_nh);

/// ~vote_ransac_max_angle_deg, ~vote_ransac_max_scale_ratio, ~vote_ransac_max_fit_points.
VoteRansacConfig readVoteRansacConfig(const ros::NodeHandle& private_nh);

/// The filter readers above: epipolar, gsc, ransac, magsac, gms, lsc, local_gsc, guided,
/// vote_ransac.
FilterConfigs readFilterConfigs(const ros::NodeHandle& private_nh);

/// ~filters, ~queue_size, ~max_waiting_pairs, ~workers, ~approximate_sync, ~calibrated,
/// ~frame_to_frame, ~image_transport, ~diagnostic_period.
MatcherNodeConfig readMatcherNodeConfig(const ros::NodeHandle& private_nh);

/// readMatcherNodeConfig, readSiftConfig, readMatchConfig and readFilterConfigs.
MatcherSettings readMatcherSettings(const ros::NodeHandle& private_nh);

/// ~world_frame, ~queue_size, ~pose_timeout_s, ~from_image, ~diagnostic_period, the
/// silhouette recipe, ~max_surface_points, ~refine_period_s and the free-space readers.
/// octomap_server's ~frame_id is read as ~world_frame; set with a different ~world_frame, it is an
/// error (std::invalid_argument naming both).
HullNodeConfig readHullNodeConfig(const ros::NodeHandle& private_nh);

/// ~stop_margin_voxels, ~min_views, ~keep_radius_voxels, ~max_edge_fraction, ~max_slant_deg,
/// ~bulge_fraction; throws std::invalid_argument for a value FreeSpaceConfig refuses.
FreeSpaceConfig readFreeSpaceConfig(const ros::NodeHandle& private_nh);

/// ~max_reprojection_px (confirm_radius_voxels confirms points by feature tracks across pairs,
/// which a SurfacePoints message does not carry: the node leaves it at its default).
SurfacePointConfig readSurfacePointConfig(const ros::NodeHandle& private_nh);

/// ~bag, ~out_dir (both required: throws std::invalid_argument without them),
/// ~hull_save_service, ~timeout_s.
ResultSaverConfig readResultSaverConfig(const ros::NodeHandle& private_nh);

/// While one is alive, records what the readers called on its thread look up: every parameter
/// name they read (deprecated names aside) and every deprecation warning they give (each time,
/// though the log shows each warning once per process). For tests: a parameter file must state
/// every name read.
class ReadLog {
 public:
  ReadLog();
  ~ReadLog();
  ReadLog(const ReadLog&) = delete;
  ReadLog& operator=(const ReadLog&) = delete;

  std::set<std::string> names;
  std::vector<std::string> warnings;

 private:
  ReadLog* outer_;
};

}  // namespace ros_params
}  // namespace sift_hull
