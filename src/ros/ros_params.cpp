#include "ros_params.h"

#include <stdexcept>

namespace sift_hull {
namespace ros_params {

SilhouetteConfig readSilhouetteConfig(const ros::NodeHandle& private_nh) {
  SilhouetteConfig config;
  private_nh.param("threshold", config.threshold, config.threshold);
  private_nh.param("dilate_px", config.dilate_px, config.dilate_px);
  private_nh.param("erode_px", config.erode_px, config.erode_px);
  if (!(config.threshold >= 0.0 && config.threshold <= 1.0) || config.dilate_px < 0 ||
      config.erode_px < 0) {
    throw std::invalid_argument("~threshold must lie in [0, 1], ~dilate_px and ~erode_px >= 0");
  }
  return config;
}

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
  private_nh.param("min_view_distance_m", config.min_view_distance_m, config.min_view_distance_m);
  private_nh.param("min_view_angle_deg", config.min_view_angle_deg, config.min_view_angle_deg);
  validate(config);
  return config;
}

SiftConfig readSiftConfig(const ros::NodeHandle& private_nh) {
  SiftConfig config;
  private_nh.param("max_features", config.max_features, config.max_features);
  private_nh.param("octave_layers", config.octave_layers, config.octave_layers);
  private_nh.param("contrast_threshold", config.contrast_threshold, config.contrast_threshold);
  private_nh.param("edge_threshold", config.edge_threshold, config.edge_threshold);
  private_nh.param("sigma_px", config.sigma_px, config.sigma_px);
  validate(config);
  return config;
}

MatchConfig readMatchConfig(const ros::NodeHandle& private_nh) {
  MatchConfig config;
  private_nh.param("ratio", config.ratio, config.ratio);
  double max_distance = 0.0;
  private_nh.param("max_descriptor_distance", max_distance, max_distance);
  if (max_distance > 0.0) config.max_descriptor_distance = max_distance;
  private_nh.param("cross_check", config.cross_check, config.cross_check);
  private_nh.param("matcher", config.backend, config.backend);
  validate(config);
  return config;
}

namespace {

void readRobustFit(const ros::NodeHandle& private_nh, const std::string& prefix,
                   RobustFitConfig* config) {
  private_nh.param(prefix + "_max_epipolar_px", config->max_epipolar_px, config->max_epipolar_px);
  private_nh.param("robust_confidence", config->confidence, config->confidence);
  private_nh.param("robust_max_iterations", config->max_iterations, config->max_iterations);
}

}  // namespace

FilterConfigs readFilterConfigs(const ros::NodeHandle& private_nh) {
  FilterConfigs configs;
  private_nh.param("max_epipolar_px", configs.epipolar.max_epipolar_px,
                   configs.epipolar.max_epipolar_px);
  GscConfig& gsc = configs.gsc;
  private_nh.param("gsc_max_histogram_distance", gsc.max_histogram_distance,
                   gsc.max_histogram_distance);
  private_nh.param("gsc_threads", gsc.threads, gsc.threads);
  readRobustFit(private_nh, "ransac", &configs.ransac);
  readRobustFit(private_nh, "magsac", &configs.magsac);
  GmsConfig& gms = configs.gms;
  private_nh.param("gms_grid_cells", gms.grid_cells, gms.grid_cells);
  private_nh.param("gms_threshold_factor", gms.threshold_factor, gms.threshold_factor);
  private_nh.param("gms_with_rotation", gms.with_rotation, gms.with_rotation);
  private_nh.param("gms_with_scale", gms.with_scale, gms.with_scale);
  validate(configs);
  return configs;
}

MatcherSettings readMatcherSettings(const ros::NodeHandle& private_nh) {
  MatcherSettings settings;
  MatcherNodeConfig& node = settings.node;
  private_nh.param("filters", node.filters, node.filters);
  private_nh.param("queue_size", node.queue_size, node.queue_size);
  private_nh.param("max_waiting_pairs", node.max_waiting_pairs, node.max_waiting_pairs);
  private_nh.param("workers", node.workers, node.workers);
  private_nh.param("approximate_sync", node.approximate_sync, node.approximate_sync);
  private_nh.param("calibrated", node.calibrated, node.calibrated);
  private_nh.param("frame_to_frame", node.frame_to_frame, node.frame_to_frame);
  settings.sift = readSiftConfig(private_nh);
  settings.matching = readMatchConfig(private_nh);
  settings.filters = readFilterConfigs(private_nh);
  return settings;
}

ResultSaverConfig readResultSaverConfig(const ros::NodeHandle& private_nh) {
  ResultSaverConfig config;
  private_nh.param("bag", config.bag, config.bag);
  private_nh.param("out_dir", config.out_dir, config.out_dir);
  private_nh.param("hull_save_service", config.hull_save_service, config.hull_save_service);
  private_nh.param("timeout_s", config.timeout_s, config.timeout_s);
  if (config.bag.empty() || config.out_dir.empty()) {
    throw std::invalid_argument("~bag and ~out_dir are required");
  }
  return config;
}

}  // namespace ros_params
}  // namespace sift_hull
