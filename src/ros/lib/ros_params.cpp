#include "lib/ros_params.h"

#include <ros/console.h>

#include <cmath>
#include <limits>
#include <mutex>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "sift_hull/filters/filter.h"
#include "sift_hull/hull/hull_config.h"
#include "sift_hull/hull/silhouette.h"

namespace sift_hull {
namespace ros_params {
namespace {

const char* typeName(bool) { return "boolean"; }
const char* typeName(double) { return "number"; }
const char* typeName(const std::string&) { return "string"; }
const char* typeName(const std::vector<double>&) { return "list of numbers"; }
const char* typeName(const std::vector<std::string>&) { return "list of strings"; }

thread_local ReadLog* active_log = nullptr;

void noteName(const std::string& name) {
  if (active_log != nullptr) active_log->names.insert(name);
}

/// Logs `message` once per node namespace and process (readers may run more than once).
void warnDeprecated(const ros::NodeHandle& private_nh, const std::string& message) {
  if (active_log != nullptr) active_log->warnings.push_back(message);
  static std::mutex mutex;
  static std::set<std::string> given;
  const std::string text = private_nh.getNamespace() + ": " + message;
  {
    std::lock_guard<std::mutex> lock(mutex);
    if (!given.insert(text).second) return;
  }
  ROS_WARN("%s", text.c_str());
}

/// Whether the parameter is set, and then its value; throws std::invalid_argument when it is set
/// with another type (e.g. a string where a list is expected), rather than quietly keeping the
/// default.
template <typename T>
bool get(const ros::NodeHandle& private_nh, const std::string& name, T* value) {
  if (!private_nh.hasParam(name)) return false;
  if (!private_nh.getParam(name, *value)) {
    throw std::invalid_argument("~" + name + " is set, but not as a " + typeName(*value));
  }
  return true;
}

/// roscpp would truncate 2.5 to 2 for an integer; here that is a wrong type too.
bool get(const ros::NodeHandle& private_nh, const std::string& name, int* value) {
  XmlRpc::XmlRpcValue raw;
  if (!private_nh.getParam(name, raw)) return false;
  if (raw.getType() != XmlRpc::XmlRpcValue::TypeInt) {
    throw std::invalid_argument("~" + name + " is set, but not as an integer");
  }
  *value = static_cast<int>(raw);
  return true;
}

/// The parameter's value when it is set (see get).
template <typename T>
void read(const ros::NodeHandle& private_nh, const std::string& name, T* value) {
  noteName(name);
  get(private_nh, name, value);
}

/// A parameter renamed from `old_name` to `name`: `name` when it is set, else `old_name`, with a
/// deprecation warning whenever `old_name` is set. Both are type-checked.
template <typename T>
void readRenamed(const ros::NodeHandle& private_nh, const std::string& name,
                 const std::string& old_name, T* value) {
  noteName(name);
  const bool has_name = get(private_nh, name, value);
  if (!private_nh.hasParam(old_name)) return;
  const std::string warning = "~" + old_name + " is deprecated, use ~" + name;
  if (has_name) {
    // Equal values are no conflict (hull.launch sets both from its deprecated `depth` arg).
    T old_value = *value;
    get(private_nh, old_name, &old_value);
    warnDeprecated(private_nh, old_value == *value
                                   ? warning
                                   : warning + " (both are set: ~" + old_name + " is ignored)");
  } else {
    get(private_nh, old_name, value);
    warnDeprecated(private_nh, warning);
  }
}

}  // namespace

double descriptorDistanceFromParam(double param) {
  return param > 0.0 ? param : std::numeric_limits<double>::infinity();
}

double descriptorDistanceParam(double distance) { return std::isfinite(distance) ? distance : 0.0; }

SilhouetteConfig readSilhouetteConfig(const ros::NodeHandle& private_nh) {
  SilhouetteConfig config;
  read(private_nh, "silhouette_method", &config.silhouette_method);
  // A threshold given asks for the threshold recipe, unless a method is named too.
  if (private_nh.hasParam("threshold") && !private_nh.hasParam("silhouette_method")) {
    config.silhouette_method = "threshold";
  }
  read(private_nh, "threshold", &config.threshold);
  read(private_nh, "dilate_px", &config.dilate_px);
  read(private_nh, "erode_px", &config.erode_px);
  validate(config);
  return config;
}

HullConfig readHullConfig(const ros::NodeHandle& private_nh) {
  HullConfig config;
  if (private_nh.hasParam("resolution")) {  // octomap_server's voxel edge
    throw std::invalid_argument(
        "~resolution (octomap_server's voxel edge) is not a hull_node parameter: set "
        "~resolution_m (metres, the same meaning) or ~max_depth");
  }
  readRenamed(private_nh, "max_depth", "depth", &config.max_depth);
  read(private_nh, "resolution_m", &config.resolution_m);
  read(private_nh, "carve_outside_image", &config.carve_outside_image);
  readRenamed(private_nh, "distance_slack_px", "slack_px", &config.distance_slack_px);
  read(private_nh, "threads", &config.threads);
  read(private_nh, "distance_reduction", &config.distance_reduction);
  validate(config);
  return config;
}

HullStreamConfig readHullStreamConfig(const ros::NodeHandle& private_nh) {
  HullStreamConfig config;
  config.hull = readHullConfig(private_nh);
  std::vector<double> box;
  read(private_nh, "box", &box);
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
  read(private_nh, "skip_views", &config.skip_views);
  read(private_nh, "min_view_distance_m", &config.min_view_distance_m);
  read(private_nh, "min_view_angle_deg", &config.min_view_angle_deg);
  read(private_nh, "max_waiting_views", &config.max_waiting_views);
  read(private_nh, "max_views", &config.max_views);
  validate(config);
  return config;
}

SiftConfig readSiftConfig(const ros::NodeHandle& private_nh) {
  SiftConfig config;
  read(private_nh, "max_features", &config.max_features);
  read(private_nh, "octave_layers", &config.octave_layers);
  read(private_nh, "contrast_threshold", &config.contrast_threshold);
  read(private_nh, "edge_threshold", &config.edge_threshold);
  read(private_nh, "sigma_px", &config.sigma_px);
  int max_image_pixels = static_cast<int>(config.max_image_pixels);
  read(private_nh, "max_image_pixels", &max_image_pixels);
  if (max_image_pixels < 1) throw std::invalid_argument("~max_image_pixels must be >= 1");
  config.max_image_pixels = static_cast<size_t>(max_image_pixels);
  validate(config);
  return config;
}

MatchConfig readMatchConfig(const ros::NodeHandle& private_nh) {
  MatchConfig config;
  read(private_nh, "ratio", &config.ratio);
  double max_distance = descriptorDistanceParam(config.max_descriptor_distance);
  read(private_nh, "max_descriptor_distance", &max_distance);
  config.max_descriptor_distance = descriptorDistanceFromParam(max_distance);
  read(private_nh, "cross_check", &config.cross_check);
  readRenamed(private_nh, "backend", "matcher", &config.backend);
  validate(config);
  return config;
}

EpipolarConfig readEpipolarConfig(const ros::NodeHandle& private_nh) {
  EpipolarConfig config;
  read(private_nh, "max_epipolar_px", &config.max_epipolar_px);
  return config;
}

GscConfig readGscConfig(const ros::NodeHandle& private_nh) {
  GscConfig config;
  readRenamed(private_nh, "max_histogram_distance", "gsc_max_histogram_distance",
              &config.max_histogram_distance);
  readRenamed(private_nh, "threads", "gsc_threads", &config.threads);
  read(private_nh, "max_support", &config.max_support);
  return config;
}

RobustFitConfig readRobustFitConfig(const ros::NodeHandle& private_nh, const std::string& prefix) {
  RobustFitConfig config;
  read(private_nh, prefix + "_max_epipolar_px", &config.max_epipolar_px);
  readRenamed(private_nh, prefix + "_confidence", "robust_confidence", &config.confidence);
  readRenamed(private_nh, prefix + "_max_iterations", "robust_max_iterations",
              &config.max_iterations);
  read(private_nh, prefix + "_seed", &config.seed);
  return config;
}

LscConfig readLscConfig(const ros::NodeHandle& private_nh) {
  LscConfig config;
  read(private_nh, "lsc_neighbours", &config.lsc_neighbours);
  read(private_nh, "lsc_max_relative_error", &config.lsc_max_relative_error);
  read(private_nh, "lsc_min_tolerance_px", &config.lsc_min_tolerance_px);
  read(private_nh, "lsc_min_support", &config.lsc_min_support);
  return config;
}

LocalGscConfig readLocalGscConfig(const ros::NodeHandle& private_nh) {
  LocalGscConfig config;
  read(private_nh, "local_gsc_neighbours", &config.local_gsc_neighbours);
  read(private_nh, "local_gsc_max_histogram_distance", &config.local_gsc_max_histogram_distance);
  return config;
}

GuidedConfig readGuidedConfig(const ros::NodeHandle& private_nh) {
  GuidedConfig config;
  read(private_nh, "guided_max_transfer_px", &config.guided_max_transfer_px);
  read(private_nh, "guided_homography_share", &config.guided_homography_share);
  read(private_nh, "guided_max_models", &config.guided_max_models);
  read(private_nh, "guided_min_model_inliers", &config.guided_min_model_inliers);
  read(private_nh, "guided_min_support", &config.guided_min_support);
  read(private_nh, "guided_max_fit_points", &config.guided_max_fit_points);
  return config;
}

VoteRansacConfig readVoteRansacConfig(const ros::NodeHandle& private_nh) {
  VoteRansacConfig config;
  read(private_nh, "vote_ransac_max_angle_deg", &config.vote_ransac_max_angle_deg);
  read(private_nh, "vote_ransac_max_scale_ratio", &config.vote_ransac_max_scale_ratio);
  read(private_nh, "vote_ransac_max_fit_points", &config.vote_ransac_max_fit_points);
  return config;
}

GmsConfig readGmsConfig(const ros::NodeHandle& private_nh) {
  GmsConfig config;
  readRenamed(private_nh, "grid_cells", "gms_grid_cells", &config.grid_cells);
  readRenamed(private_nh, "threshold_factor", "gms_threshold_factor", &config.threshold_factor);
  readRenamed(private_nh, "with_rotation", "gms_with_rotation", &config.with_rotation);
  readRenamed(private_nh, "with_scale", "gms_with_scale", &config.with_scale);
  return config;
}

FilterConfigs readFilterConfigs(const ros::NodeHandle& private_nh) {
  FilterConfigs configs;
  configs.epipolar = readEpipolarConfig(private_nh);
  configs.gsc = readGscConfig(private_nh);
  configs.ransac = readRobustFitConfig(private_nh, "ransac");
  configs.magsac = readRobustFitConfig(private_nh, "magsac");
  configs.gms = readGmsConfig(private_nh);
  configs.lsc = readLscConfig(private_nh);
  configs.local_gsc = readLocalGscConfig(private_nh);
  configs.guided = readGuidedConfig(private_nh);
  configs.vote_ransac = readVoteRansacConfig(private_nh);
  validate(configs);
  return configs;
}

namespace {

/// ~diagnostic_period, also read by diagnostic_updater itself: seconds between /diagnostics.
double readDiagnosticPeriod(const ros::NodeHandle& private_nh, double period_s) {
  read(private_nh, "diagnostic_period", &period_s);
  if (!(period_s > 0.0) || !std::isfinite(period_s)) {
    throw std::invalid_argument("~diagnostic_period must be a number > 0 (seconds)");
  }
  return period_s;
}

}  // namespace

MatcherNodeConfig readMatcherNodeConfig(const ros::NodeHandle& private_nh) {
  MatcherNodeConfig config;
  read(private_nh, "filters", &config.filters);
  read(private_nh, "queue_size", &config.queue_size);
  read(private_nh, "max_waiting_pairs", &config.max_waiting_pairs);
  read(private_nh, "workers", &config.workers);
  read(private_nh, "approximate_sync", &config.approximate_sync);
  read(private_nh, "calibrated", &config.calibrated);
  read(private_nh, "rectified", &config.rectified);
  read(private_nh, "frame_to_frame", &config.frame_to_frame);
  read(private_nh, "image_transport", &config.image_transport);
  config.diagnostic_period = readDiagnosticPeriod(private_nh, config.diagnostic_period);
  if (config.queue_size < 1 || config.max_waiting_pairs < 1 || config.workers < 1) {
    throw std::invalid_argument("~queue_size, ~max_waiting_pairs and ~workers must be at least 1");
  }
  return config;
}

MatcherSettings readMatcherSettings(const ros::NodeHandle& private_nh) {
  MatcherSettings settings;
  settings.node = readMatcherNodeConfig(private_nh);
  settings.sift = readSiftConfig(private_nh);
  settings.matching = readMatchConfig(private_nh);
  settings.filters = readFilterConfigs(private_nh);
  return settings;
}

namespace {

/// ~world_frame, or octomap_server's ~frame_id for it; both set and different: an error.
std::string readWorldFrame(const ros::NodeHandle& private_nh, std::string world_frame) {
  read(private_nh, "world_frame", &world_frame);
  std::string frame_id;
  if (!get(private_nh, "frame_id", &frame_id)) return world_frame;
  if (private_nh.hasParam("world_frame") && frame_id != world_frame) {
    throw std::invalid_argument("~frame_id ('" + frame_id + "', octomap_server's map frame) and " +
                                "~world_frame ('" + world_frame +
                                "') differ: set ~world_frame only");
  }
  return frame_id;
}

}  // namespace

HullNodeConfig readHullNodeConfig(const ros::NodeHandle& private_nh) {
  HullNodeConfig config;
  config.world_frame = readWorldFrame(private_nh, config.world_frame);
  read(private_nh, "queue_size", &config.queue_size);
  read(private_nh, "pose_timeout_s", &config.pose_timeout_s);
  read(private_nh, "from_image", &config.from_image);
  read(private_nh, "rectified", &config.rectified);
  config.diagnostic_period = readDiagnosticPeriod(private_nh, config.diagnostic_period);
  config.recipe = readSilhouetteConfig(private_nh);
  read(private_nh, "max_surface_points", &config.max_surface_points);
  read(private_nh, "refine_period_s", &config.refine_period_s);
  config.surface_points = readSurfacePointConfig(private_nh);
  config.free_space = readFreeSpaceConfig(private_nh);
  if (config.max_surface_points < 1) {
    throw std::invalid_argument("~max_surface_points must be at least 1");
  }
  if (!(config.refine_period_s > 0.0) || !std::isfinite(config.refine_period_s)) {
    throw std::invalid_argument("~refine_period_s must be a number > 0");
  }
  if (config.queue_size < 1) throw std::invalid_argument("~queue_size must be at least 1");
  if (!std::isfinite(config.pose_timeout_s)) {
    throw std::invalid_argument("~pose_timeout_s must be a number");
  }
  return config;
}

FreeSpaceConfig readFreeSpaceConfig(const ros::NodeHandle& private_nh) {
  FreeSpaceConfig config;
  read(private_nh, "stop_margin_voxels", &config.stop_margin_voxels);
  read(private_nh, "min_views", &config.min_views);
  read(private_nh, "keep_radius_voxels", &config.keep_radius_voxels);
  read(private_nh, "max_edge_fraction", &config.max_edge_fraction);
  read(private_nh, "max_slant_deg", &config.max_slant_deg);
  read(private_nh, "bulge_fraction", &config.bulge_fraction);
  validate(config);
  return config;
}

SurfacePointConfig readSurfacePointConfig(const ros::NodeHandle& private_nh) {
  SurfacePointConfig config;
  read(private_nh, "max_reprojection_px", &config.max_reprojection_px);
  validate(config);
  return config;
}

ResultSaverConfig readResultSaverConfig(const ros::NodeHandle& private_nh) {
  ResultSaverConfig config;
  read(private_nh, "bag", &config.bag);
  read(private_nh, "out_dir", &config.out_dir);
  read(private_nh, "hull_save_service", &config.hull_save_service);
  read(private_nh, "timeout_s", &config.timeout_s);
  if (config.bag.empty() || config.out_dir.empty()) {
    throw std::invalid_argument("~bag and ~out_dir are required");
  }
  return config;
}

ReadLog::ReadLog() : outer_(active_log) { active_log = this; }

ReadLog::~ReadLog() { active_log = outer_; }

}  // namespace ros_params
}  // namespace sift_hull
