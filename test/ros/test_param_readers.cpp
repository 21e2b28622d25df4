// The parameter readers against a real parameter server: the parameter files in config/ restate
// the config structs' defaults and state every parameter the readers read, unset parameters give
// those defaults, set ones are read, a parameter of the wrong type or value is an error rather
// than a silent default, and filter settings are named by their filter.

#include <gtest/gtest.h>
#include <ros/ros.h>

#include <cmath>
#include <functional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "lib/ros_params.h"
#include "sift_hull/MatcherConfig.h"
#include "sift_hull/filters/filter.h"

namespace sift_hull {
namespace {

using ros_params::readHullNodeConfig;
using ros_params::readHullStreamConfig;
using ros_params::ReadLog;
using ros_params::readMatcherSettings;

void readHull(const ros::NodeHandle& nh) {
  readHullNodeConfig(nh);
  readHullStreamConfig(nh);
}

void readMatcher(const ros::NodeHandle& nh) { readMatcherSettings(nh); }

/// The names `read` reads on `nh`.
std::set<std::string> namesRead(const std::function<void(const ros::NodeHandle&)>& read,
                                const ros::NodeHandle& nh) {
  ReadLog log;
  read(nh);
  return log.names;
}

void expectDefaultHull(const ros::NodeHandle& nh) {
  const HullNodeConfig node = readHullNodeConfig(nh), node_default;
  EXPECT_EQ(node.world_frame, node_default.world_frame);
  EXPECT_EQ(node.queue_size, node_default.queue_size);
  EXPECT_EQ(node.pose_timeout_s, node_default.pose_timeout_s);
  EXPECT_EQ(node.from_image, node_default.from_image);
  EXPECT_EQ(node.rectified, node_default.rectified);
  EXPECT_EQ(node.diagnostic_period, node_default.diagnostic_period);
  EXPECT_EQ(node.recipe.silhouette_method, node_default.recipe.silhouette_method);
  EXPECT_EQ(node.recipe.threshold, node_default.recipe.threshold);
  EXPECT_EQ(node.recipe.dilate_px, node_default.recipe.dilate_px);
  EXPECT_EQ(node.recipe.erode_px, node_default.recipe.erode_px);
  const HullStreamConfig hull = readHullStreamConfig(nh), hull_default;
  EXPECT_EQ(hull.hull.max_depth, hull_default.hull.max_depth);
  EXPECT_EQ(hull.hull.carve_outside_image, hull_default.hull.carve_outside_image);
  EXPECT_EQ(hull.hull.distance_slack_px, hull_default.hull.distance_slack_px);
  EXPECT_EQ(hull.hull.threads, hull_default.hull.threads);
  EXPECT_EQ(hull.hull.distance_reduction, hull_default.hull.distance_reduction);
  EXPECT_FALSE(hull.box.has_value());
  EXPECT_TRUE(hull.skip_views.empty());
  EXPECT_EQ(hull.min_view_distance_m, hull_default.min_view_distance_m);
  EXPECT_EQ(hull.min_view_angle_deg, hull_default.min_view_angle_deg);
  EXPECT_EQ(hull.max_waiting_views, hull_default.max_waiting_views);
  EXPECT_EQ(hull.max_views, hull_default.max_views);
}

void expectDefaultMatcher(const ros::NodeHandle& nh) {
  const MatcherSettings read = readMatcherSettings(nh), standard;
  EXPECT_EQ(read.node.filters, standard.node.filters);
  EXPECT_EQ(read.node.queue_size, standard.node.queue_size);
  EXPECT_EQ(read.node.max_waiting_pairs, standard.node.max_waiting_pairs);
  EXPECT_EQ(read.node.workers, standard.node.workers);
  EXPECT_EQ(read.node.approximate_sync, standard.node.approximate_sync);
  EXPECT_EQ(read.node.calibrated, standard.node.calibrated);
  EXPECT_EQ(read.node.rectified, standard.node.rectified);
  EXPECT_EQ(read.node.frame_to_frame, standard.node.frame_to_frame);
  EXPECT_EQ(read.node.image_transport, standard.node.image_transport);
  EXPECT_EQ(read.node.diagnostic_period, standard.node.diagnostic_period);
  EXPECT_EQ(read.sift.max_features, standard.sift.max_features);
  EXPECT_EQ(read.sift.octave_layers, standard.sift.octave_layers);
  EXPECT_EQ(read.sift.contrast_threshold, standard.sift.contrast_threshold);
  EXPECT_EQ(read.sift.edge_threshold, standard.sift.edge_threshold);
  EXPECT_EQ(read.sift.sigma_px, standard.sift.sigma_px);
  EXPECT_EQ(read.sift.max_image_pixels, standard.sift.max_image_pixels);
  EXPECT_EQ(read.matching.ratio, standard.matching.ratio);
  EXPECT_EQ(read.matching.max_descriptor_distance, standard.matching.max_descriptor_distance);
  EXPECT_EQ(read.matching.cross_check, standard.matching.cross_check);
  EXPECT_EQ(read.matching.backend, standard.matching.backend);
  const FilterConfigs& f = read.filters;
  const FilterConfigs& g = standard.filters;
  EXPECT_EQ(f.epipolar.max_distance_px, g.epipolar.max_distance_px);
  EXPECT_EQ(f.gsc.max_histogram_distance, g.gsc.max_histogram_distance);
  EXPECT_EQ(f.gsc.threads, g.gsc.threads);
  for (const auto& [got, want] : {std::pair(f.ransac, g.ransac), std::pair(f.magsac, g.magsac)}) {
    EXPECT_EQ(got.max_epipolar_px, want.max_epipolar_px);
    EXPECT_EQ(got.confidence, want.confidence);
    EXPECT_EQ(got.max_iterations, want.max_iterations);
  }
  EXPECT_EQ(f.gms.grid_cells, g.gms.grid_cells);
  EXPECT_EQ(f.gms.threshold_factor, g.gms.threshold_factor);
  EXPECT_EQ(f.gms.with_rotation, g.gms.with_rotation);
  EXPECT_EQ(f.gms.with_scale, g.gms.with_scale);
  EXPECT_EQ(f.gsc.max_support, g.gsc.max_support);
  EXPECT_EQ(f.ransac.seed, g.ransac.seed);
  EXPECT_EQ(f.magsac.seed, g.magsac.seed);
  EXPECT_EQ(f.lsc.neighbours, g.lsc.neighbours);
  EXPECT_EQ(f.lsc.max_relative_error, g.lsc.max_relative_error);
  EXPECT_EQ(f.lsc.min_tolerance_px, g.lsc.min_tolerance_px);
  EXPECT_EQ(f.lsc.min_support, g.lsc.min_support);
  EXPECT_EQ(f.local_gsc.neighbours, g.local_gsc.neighbours);
  EXPECT_EQ(f.local_gsc.max_histogram_distance,
            g.local_gsc.max_histogram_distance);
  EXPECT_EQ(f.guided.max_transfer_px, g.guided.max_transfer_px);
  EXPECT_EQ(f.guided.homography_share, g.guided.homography_share);
  EXPECT_EQ(f.guided.max_models, g.guided.max_models);
  EXPECT_EQ(f.guided.min_model_inliers, g.guided.min_model_inliers);
  EXPECT_EQ(f.guided.min_support, g.guided.min_support);
  EXPECT_EQ(f.guided.max_fit_points, g.guided.max_fit_points);
  EXPECT_EQ(f.vote_ransac.max_angle_deg, g.vote_ransac.max_angle_deg);
  EXPECT_EQ(f.vote_ransac.max_scale_ratio, g.vote_ransac.max_scale_ratio);
  EXPECT_EQ(f.vote_ransac.max_fit_points, g.vote_ransac.max_fit_points);
}

TEST(ParameterReaders, TheParameterFilesRestateTheStructDefaults) {
  // param_readers.test loads config/hull.yaml into /hull_yaml and config/matcher.yaml into
  // /matcher_yaml.
  ASSERT_TRUE(ros::param::has("/hull_yaml/max_depth"));
  ASSERT_TRUE(ros::param::has("/matcher_yaml/filters"));
  expectDefaultHull(ros::NodeHandle("/hull_yaml"));
  expectDefaultMatcher(ros::NodeHandle("/matcher_yaml"));
}

/// Whether `read` looks at the parameter `key` of the file loaded into `ns`: a copy of the file
/// with that key set to a dictionary, a type no reader takes, must be refused.
bool isRead(const std::string& ns, const std::string& key,
            const std::function<void(const ros::NodeHandle&)>& read) {
  XmlRpc::XmlRpcValue file;
  if (!ros::param::get(ns, file)) return false;
  XmlRpc::XmlRpcValue dictionary;
  dictionary["not"] = "a parameter value";
  file[key] = dictionary;
  const std::string probe = "/probe" + ns + "_" + key;
  ros::param::set(probe, file);
  try {
    read(ros::NodeHandle(probe));
  } catch (const std::invalid_argument&) {
    return true;
  }
  return false;
}

TEST(ParameterReaders, EveryKeyOfTheParameterFilesIsRead) {
  for (const auto& [ns, read] :
       {std::pair<std::string, std::function<void(const ros::NodeHandle&)>>("/hull_yaml", readHull),
        {"/matcher_yaml", readMatcher}}) {
    XmlRpc::XmlRpcValue file;
    ASSERT_TRUE(ros::param::get(ns, file));
    ASSERT_EQ(file.getType(), XmlRpc::XmlRpcValue::TypeStruct);
    for (const auto& [key, value] : file) {
      EXPECT_TRUE(isRead(ns, key, read)) << ns << "/" << key << " is not read by any reader";
    }
  }
}

TEST(ParameterReaders, TheParameterFilesStateEveryParameterRead) {
  for (const auto& [ns, read] :
       {std::pair<std::string, std::function<void(const ros::NodeHandle&)>>("/hull_yaml", readHull),
        {"/matcher_yaml", readMatcher}}) {
    XmlRpc::XmlRpcValue file;
    ASSERT_TRUE(ros::param::get(ns, file));
    const std::set<std::string> names = namesRead(read, ros::NodeHandle("/nothing_set"));
    EXPECT_GE(names.size(), 15u) << ns;
    for (const std::string& name : names) {
      EXPECT_TRUE(file.hasMember(name)) << name << " is read but not stated in the file of " << ns;
    }
    EXPECT_EQ(names.size(), static_cast<size_t>(file.size())) << ns;
  }
}

TEST(ParameterReaders, TheReconfigureSettingsAreMatcherParameters) {
  const std::set<std::string> names = namesRead(readMatcher, ros::NodeHandle("/nothing_set"));
  for (const auto& description : MatcherConfig::__getParamDescriptions__()) {
    EXPECT_EQ(names.count(description->name), 1u)
        << description->name << " (cfg/Matcher.cfg) is not a matcher parameter";
  }
}

TEST(ParameterReaders, UnsetParametersGiveTheStructDefaults) {
  expectDefaultHull(ros::NodeHandle("/nothing_set"));
  expectDefaultMatcher(ros::NodeHandle("/nothing_set"));
}

TEST(ParameterReaders, SetParametersAreRead) {
  ros::NodeHandle nh("/set");
  nh.setParam("max_depth", 6);
  nh.setParam("box", std::vector<double>{-1, -2, -3, 1, 2, 3});
  nh.setParam("skip_views", std::vector<std::string>{"view_0003"});
  nh.setParam("min_view_distance_m", 0);  // an integer where a number is expected is fine
  nh.setParam("filters", std::vector<std::string>{"gsc", "magsac"});
  nh.setParam("max_descriptor_distance", 250.0);
  nh.setParam("image_transport", "compressed");
  nh.setParam("rectified", true);
  EXPECT_TRUE(readHullNodeConfig(nh).rectified);
  const HullStreamConfig hull = readHullStreamConfig(nh);
  EXPECT_EQ(hull.hull.max_depth, 6);
  ASSERT_TRUE(hull.box.has_value());
  EXPECT_EQ(hull.box->max_W, Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(hull.skip_views, std::vector<std::string>{"view_0003"});
  EXPECT_EQ(hull.min_view_distance_m, 0.0);
  const MatcherSettings matcher = readMatcherSettings(nh);
  EXPECT_EQ(matcher.node.filters, (std::vector<std::string>{"gsc", "magsac"}));
  EXPECT_EQ(matcher.matching.max_descriptor_distance, 250.0);
  EXPECT_EQ(matcher.node.image_transport, "compressed");
}

TEST(ParameterReaders, WrongTypesAndValuesAreErrors) {
  const auto hull_with = [](const std::string& name, const auto& value) {
    ros::NodeHandle nh("/bad_" + name);
    nh.setParam(name, value);
    return nh;
  };
  EXPECT_THROW(readHullStreamConfig(hull_with("box", std::string("[1,2,3,4,5,6]"))),
               std::invalid_argument);  // a string, as `_box:=[...]` on a command line gives
  EXPECT_THROW(readHullStreamConfig(hull_with("box", std::vector<double>{1, 2, 3})),
               std::invalid_argument);
  EXPECT_THROW(readHullStreamConfig(hull_with("max_depth", 6.5)), std::invalid_argument);
  EXPECT_THROW(readHullStreamConfig(hull_with("min_view_angle_deg", -1.0)), std::invalid_argument);
  EXPECT_THROW(readHullNodeConfig(hull_with("from_image", std::string("yes"))),
               std::invalid_argument);
  EXPECT_THROW(readMatcherSettings(hull_with("filters", std::string("gsc"))),
               std::invalid_argument);
  EXPECT_THROW(readMatcherSettings(hull_with("ratio", std::string("0.8"))), std::invalid_argument);
  EXPECT_THROW(readHullNodeConfig(hull_with("queue_size", 0)), std::invalid_argument);
  EXPECT_THROW(readMatcherSettings(hull_with("max_waiting_pairs", -1)), std::invalid_argument);
  EXPECT_THROW(readMatcherSettings(hull_with("workers", 0)), std::invalid_argument);
  EXPECT_THROW(readHullNodeConfig(hull_with("diagnostic_period", 0.0)), std::invalid_argument);
  EXPECT_THROW(readMatcherSettings(hull_with("diagnostic_period", std::string("1"))),
               std::invalid_argument);
}

/// The message of the std::invalid_argument that `read` throws ("" when it throws none).
std::string refusal(const std::function<void()>& read) {
  try {
    read();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(ParameterReaders, FilterSettingsAreNamedByTheirFilter) {
  ros::NodeHandle nh("/filter_names");
  nh.setParam("epipolar_max_distance_px", 3.0);
  nh.setParam("gsc_max_histogram_distance", 0.3);
  nh.setParam("gsc_threads", 3);
  nh.setParam("ransac_confidence", 0.95);
  nh.setParam("magsac_max_iterations", 500);
  nh.setParam("gms_grid_cells", 10);
  nh.setParam("lsc_max_relative_error", 0.5);
  nh.setParam("vote_ransac_max_fit_points", 300);
  ReadLog log;
  const FilterConfigs f = readMatcherSettings(nh).filters;
  EXPECT_EQ(f.epipolar.max_distance_px, 3.0);
  EXPECT_EQ(f.gsc.max_histogram_distance, 0.3);
  EXPECT_EQ(f.gsc.threads, 3);
  EXPECT_EQ(f.ransac.confidence, 0.95);
  EXPECT_EQ(f.magsac.confidence, FilterConfigs().magsac.confidence);  // each instance its own
  EXPECT_EQ(f.magsac.max_iterations, 500);
  EXPECT_EQ(f.gms.grid_cells, 10);
  EXPECT_EQ(f.lsc.max_relative_error, 0.5);
  EXPECT_EQ(f.vote_ransac.max_fit_points, 300);
  for (const char* bare : {"grid_cells", "max_histogram_distance", "max_relative_error"}) {
    EXPECT_EQ(log.names.count(bare), 0u) << bare;
  }
}

TEST(ParameterReaders, AValueOutOfRangeIsRefusedNamingItsParameter) {
  ros::NodeHandle nh("/out_of_range");
  nh.setParam("lsc_min_support", 2.0);
  const std::string refused = refusal([&] { readMatcherSettings(nh); });
  EXPECT_NE(refused.find("~lsc_min_support must be"), std::string::npos) << refused;
  EXPECT_NE(refused.find("[0, 0.3]"), std::string::npos) << refused;
  ros::NodeHandle nan("/not_a_number");
  nan.setParam("max_descriptor_distance", std::nan(""));
  EXPECT_NE(refusal([&] { readMatcherSettings(nan); }).find("~max_descriptor_distance"),
            std::string::npos);
}

TEST(ParameterReaders, AWorldFrameMustBeATf2FrameAndANanTimeoutIsNamed) {
  ros::NodeHandle empty("/empty_world_frame");
  empty.setParam("world_frame", std::string());
  EXPECT_NE(refusal([&] { readHullNodeConfig(empty); }).find("~world_frame must name a frame"),
            std::string::npos);
  ros::NodeHandle slash("/slashed_world_frame");
  slash.setParam("world_frame", std::string("/world"));
  EXPECT_NE(refusal([&] { readHullNodeConfig(slash); }).find("which tf2 refuses: write 'world'"),
            std::string::npos)
      << refusal([&] { readHullNodeConfig(slash); });
  // The matcher's world frame counts only in calibrated frame to frame.
  EXPECT_EQ(refusal([&] { readMatcherSettings(slash); }), "");
  slash.setParam("frame_to_frame", true);
  slash.setParam("calibrated", true);
  EXPECT_NE(refusal([&] { readMatcherSettings(slash); }).find("~world_frame '/world'"),
            std::string::npos);
  // A number with no range is "a finite number", not "a finite number any".
  ros::NodeHandle nan("/nan_pose_timeout");
  nan.setParam("pose_timeout_s", std::nan(""));
  EXPECT_EQ(refusal([&] { readMatcherSettings(nan); }),
            "~pose_timeout_s must be a finite number, not nan");
}

TEST(ParameterReaders, OctomapServersNamesAreReadOrRefusedNamingOurs) {
  ros::NodeHandle frame_id("/octomap_frame_id");
  frame_id.setParam("frame_id", "map");
  ReadLog log;
  EXPECT_EQ(readHullNodeConfig(frame_id).world_frame, "map");  // ~frame_id alone: the world
  EXPECT_EQ(log.names.count("frame_id"), 0u);  // not a name the parameter files need to state
  frame_id.setParam("world_frame", "map");
  EXPECT_EQ(readHullNodeConfig(frame_id).world_frame, "map");  // both, agreeing
  frame_id.setParam("world_frame", "odom");
  const std::string differ = refusal([&] { readHullNodeConfig(frame_id); });
  EXPECT_NE(differ.find("~frame_id ('map'"), std::string::npos) << differ;
  EXPECT_NE(differ.find("~world_frame ('odom')"), std::string::npos) << differ;
  ros::NodeHandle resolution("/octomap_resolution");
  resolution.setParam("resolution", 0.05);
  const std::string refused = refusal([&] { readHullStreamConfig(resolution); });
  EXPECT_NE(refused.find("~resolution"), std::string::npos) << refused;
  EXPECT_NE(refused.find("set ~resolution_m"), std::string::npos) << refused;
  ros::NodeHandle metres("/hull_resolution_m");
  metres.setParam("resolution_m", 0.004);
  EXPECT_EQ(readHullStreamConfig(metres).hull.resolution_m, 0.004);
  metres.setParam("resolution_m", -1.0);
  EXPECT_NE(refusal([&] { readHullStreamConfig(metres); }).find("resolution_m"), std::string::npos);
}

}  // namespace
}  // namespace sift_hull

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_param_readers");
  ros::NodeHandle nh;
  return RUN_ALL_TESTS();
}
