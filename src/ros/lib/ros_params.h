#pragma once

// One reader per config struct; every fallback is the struct's own default. A parameter that is
// set with the wrong type (a string where a list is expected, 2.5 for an integer) is an error
// (std::invalid_argument), not a silent default.

#include <ros/node_handle.h>

#include "nodes/hull_node.h"
#include "nodes/matcher_node.h"
#include "lib/result_saver.h"
#include "sift_hull/io/calibration.h"
#include "sift_hull/hull/hull_stream.h"
#include "sift_hull/filters/filter.h"
#include "sift_hull/hull/hull_config.h"
#include "sift_hull/hull/silhouette.h"

namespace sift_hull {
namespace ros_params {

/// ~max_descriptor_distance, and its dynamic_reconfigure setting, write "no limit" as 0;
/// MatchConfig writes it as infinity.
double descriptorDistanceFromParam(double param);
double descriptorDistanceParam(double distance);

/// ~threshold (grey level in [0, 1]), ~dilate_px, ~erode_px: the Middlebury silhouette recipe.
SilhouetteConfig readSilhouetteConfig(const ros::NodeHandle& private_nh);

/// ~depth, ~carve_outside_image, ~slack_px, ~threads.
HullConfig readHullConfig(const ros::NodeHandle& private_nh);

/// The hull config, ~box ([xmin, ymin, zmin, xmax, ymax, zmax] in the world frame, metres; empty
/// or absent: automatic), ~skip_views (frame ids of silhouettes to leave out),
/// ~min_view_distance_m and ~min_view_angle_deg. Throws std::invalid_argument for a box that is not
/// six numbers with max > min, or a negative view separation.
HullStreamConfig readHullStreamConfig(const ros::NodeHandle& private_nh);

/// ~max_features, ~octave_layers, ~contrast_threshold, ~edge_threshold, ~sigma_px.
SiftConfig readSiftConfig(const ros::NodeHandle& private_nh);

/// ~ratio, ~max_descriptor_distance (<= 0: none), ~cross_check, ~matcher.
MatchConfig readMatchConfig(const ros::NodeHandle& private_nh);

/// ~max_epipolar_px, ~gsc_max_histogram_distance, ~gsc_threads, ~ransac_max_epipolar_px,
/// ~magsac_max_epipolar_px, ~robust_confidence, ~robust_max_iterations, ~gms_grid_cells,
/// ~gms_threshold_factor, ~gms_with_rotation, ~gms_with_scale.
FilterConfigs readFilterConfigs(const ros::NodeHandle& private_nh);

/// The readers above and ~filters, ~queue_size, ~max_waiting_pairs, ~workers, ~approximate_sync,
/// ~calibrated, ~frame_to_frame, ~image_transport.
MatcherSettings readMatcherSettings(const ros::NodeHandle& private_nh);

/// ~world_frame, ~queue_size, ~pose_timeout_s, ~from_image and the silhouette recipe.
HullNodeConfig readHullNodeConfig(const ros::NodeHandle& private_nh);

/// ~bag, ~out_dir (both required: throws std::invalid_argument without them),
/// ~hull_save_service, ~timeout_s.
ResultSaverConfig readResultSaverConfig(const ros::NodeHandle& private_nh);

}  // namespace ros_params
}  // namespace sift_hull
