#include "lib/ros_params.h"

#include <cmath>
#include <limits>
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

/// The parameter's value when it is set; throws std::invalid_argument when it is set with another
/// type (e.g. a string where a list is expected), rather than quietly keeping the default.
template <typename T>
void read(const ros::NodeHandle& private_nh, const std::string& name, T* value) {
  if (!private_nh.hasParam(name)) return;
  if (!private_nh.getParam(name, *value)) {
    throw std::invalid_argument("~" + name + " is set, but not as a " + typeName(*value));
  }
}

/// roscpp would truncate 2.5 to 2 for an integer; here that is a wrong type too.
void read(const ros::NodeHandle& private_nh, const std::string& name, int* value) {
  XmlRpc::XmlRpcValue raw;
  if (!private_nh.getParam(name, raw)) return;
  if (raw.getType() != XmlRpc::XmlRpcValue::TypeInt) {
    throw std::invalid_argument("~" + name + " is set, but not as an integer");
  }
  *value = static_cast<int>(raw);
}

}  // namespace

double descriptorDistanceFromParam(double param) {
  return param > 0.0 ? param : std::numeric_limits<double>::infinity();
}

double descriptorDistanceParam(double distance) { return std::isfinite(distance) ? distance : 0.0; }

SilhouetteConfig readSilhouetteConfig(const ros::NodeHandle& private_nh) {
  SilhouetteConfig config;
  read(private_nh, "threshold", &config.threshold);
  read(private_nh, "dilate_px", &config.dilate_px);
  read(private_nh, "erode_px", &config.erode_px);
  validate(config);
  return config;
}

HullConfig readHullConfig(const ros::NodeHandle& private_nh) {
  HullConfig config;
  read(private_nh, "depth", &config.max_depth);
  read(private_nh, "carve_outside_image", &config.carve_outside_image);
  read(private_nh, "slack_px", &config.distance_slack_px);
  read(private_nh, "threads", &config.threads);
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
  read(private_nh, "matcher", &config.backend);
  validate(config);
  return config;
}

namespace {

void readRobustFit(const ros::NodeHandle& private_nh, const std::string& prefix,
                   RobustFitConfig* config) {
  read(private_nh, prefix + "_max_epipolar_px", &config->max_epipolar_px);
  read(private_nh, "robust_confidence", &config->confidence);
  read(private_nh, "robust_max_iterations", &config->max_iterations);
}

}  // namespace

FilterConfigs readFilterConfigs(const ros::NodeHandle& private_nh) {
  FilterConfigs configs;
  read(private_nh, "max_epipolar_px", &configs.epipolar.max_epipolar_px);
  GscConfig& gsc = configs.gsc;
  read(private_nh, "gsc_max_histogram_distance", &gsc.max_histogram_distance);
  read(private_nh, "gsc_threads", &gsc.threads);
  readRobustFit(private_nh, "ransac", &configs.ransac);
  readRobustFit(private_nh, "magsac", &configs.magsac);
  GmsConfig& gms = configs.gms;
  read(private_nh, "gms_grid_cells", &gms.grid_cells);
  read(private_nh, "gms_threshold_factor", &gms.threshold_factor);
  read(private_nh, "gms_with_rotation", &gms.with_rotation);
  read(private_nh, "gms_with_scale", &gms.with_scale);
  validate(configs);
  return configs;
}

MatcherSettings readMatcherSettings(const ros::NodeHandle& private_nh) {
  MatcherSettings settings;
  MatcherNodeConfig& node = settings.node;
  read(private_nh, "filters", &node.filters);
  read(private_nh, "queue_size", &node.queue_size);
  read(private_nh, "max_waiting_pairs", &node.max_waiting_pairs);
  read(private_nh, "workers", &node.workers);
  read(private_nh, "approximate_sync", &node.approximate_sync);
  read(private_nh, "calibrated", &node.calibrated);
  read(private_nh, "frame_to_frame", &node.frame_to_frame);
  read(private_nh, "image_transport", &node.image_transport);
  if (node.queue_size < 1 || node.max_waiting_pairs < 1 || node.workers < 1) {
    throw std::invalid_argument("~queue_size, ~max_waiting_pairs and ~workers must be at least 1");
  }
  settings.sift = readSiftConfig(private_nh);
  settings.matching = readMatchConfig(private_nh);
  settings.filters = readFilterConfigs(private_nh);
  return settings;
}

HullNodeConfig readHullNodeConfig(const ros::NodeHandle& private_nh) {
  HullNodeConfig config;
  read(private_nh, "world_frame", &config.world_frame);
  read(private_nh, "queue_size", &config.queue_size);
  read(private_nh, "pose_timeout_s", &config.pose_timeout_s);
  read(private_nh, "from_image", &config.from_image);
  config.recipe = readSilhouetteConfig(private_nh);
  if (config.queue_size < 1) throw std::invalid_argument("~queue_size must be at least 1");
  if (!std::isfinite(config.pose_timeout_s)) {
    throw std::invalid_argument("~pose_timeout_s must be a number");
  }
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

}  // namespace ros_params
}  // namespace sift_hull
