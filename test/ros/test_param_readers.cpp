// The parameter readers against a real parameter server: the parameter files in config/ restate
// the config structs' defaults, unset parameters give those defaults, set ones are read, and a
// parameter of the wrong type or value is an error rather than a silent default.

#include <gtest/gtest.h>
#include <ros/ros.h>

#include <functional>
#include <string>
#include <utility>

#include "lib/ros_params.h"

#include "sift_hull/filters/filter.h"

namespace sift_hull {
namespace {

using ros_params::readHullNodeConfig;
using ros_params::readHullStreamConfig;
using ros_params::readMatcherSettings;

void expectDefaultHull(const ros::NodeHandle& nh) {
  const HullNodeConfig node = readHullNodeConfig(nh), node_default;
  EXPECT_EQ(node.world_frame, node_default.world_frame);
  EXPECT_EQ(node.queue_size, node_default.queue_size);
  EXPECT_EQ(node.pose_timeout_s, node_default.pose_timeout_s);
  EXPECT_EQ(node.from_image, node_default.from_image);
  EXPECT_EQ(node.recipe.threshold, node_default.recipe.threshold);
  EXPECT_EQ(node.recipe.dilate_px, node_default.recipe.dilate_px);
  EXPECT_EQ(node.recipe.erode_px, node_default.recipe.erode_px);
  const HullStreamConfig hull = readHullStreamConfig(nh), hull_default;
  EXPECT_EQ(hull.hull.max_depth, hull_default.hull.max_depth);
  EXPECT_EQ(hull.hull.carve_outside_image, hull_default.hull.carve_outside_image);
  EXPECT_EQ(hull.hull.distance_slack_px, hull_default.hull.distance_slack_px);
  EXPECT_EQ(hull.hull.threads, hull_default.hull.threads);
  EXPECT_FALSE(hull.box.has_value());
  EXPECT_TRUE(hull.skip_views.empty());
  EXPECT_EQ(hull.min_view_distance_m, hull_default.min_view_distance_m);
  EXPECT_EQ(hull.min_view_angle_deg, hull_default.min_view_angle_deg);
}

void expectDefaultMatcher(const ros::NodeHandle& nh) {
  const MatcherSettings read = readMatcherSettings(nh), standard;
  EXPECT_EQ(read.node.filters, standard.node.filters);
  EXPECT_EQ(read.node.queue_size, standard.node.queue_size);
  EXPECT_EQ(read.node.max_waiting_pairs, standard.node.max_waiting_pairs);
  EXPECT_EQ(read.node.workers, standard.node.workers);
  EXPECT_EQ(read.node.approximate_sync, standard.node.approximate_sync);
  EXPECT_EQ(read.node.calibrated, standard.node.calibrated);
  EXPECT_EQ(read.node.frame_to_frame, standard.node.frame_to_frame);
  EXPECT_EQ(read.node.image_transport, standard.node.image_transport);
  EXPECT_EQ(read.sift.max_features, standard.sift.max_features);
  EXPECT_EQ(read.sift.octave_layers, standard.sift.octave_layers);
  EXPECT_EQ(read.sift.contrast_threshold, standard.sift.contrast_threshold);
  EXPECT_EQ(read.sift.edge_threshold, standard.sift.edge_threshold);
  EXPECT_EQ(read.sift.sigma_px, standard.sift.sigma_px);
  EXPECT_EQ(read.matching.ratio, standard.matching.ratio);
  EXPECT_EQ(read.matching.max_descriptor_distance, standard.matching.max_descriptor_distance);
  EXPECT_EQ(read.matching.cross_check, standard.matching.cross_check);
  EXPECT_EQ(read.matching.backend, standard.matching.backend);
  const FilterConfigs& f = read.filters;
  const FilterConfigs& g = standard.filters;
  EXPECT_EQ(f.epipolar.max_epipolar_px, g.epipolar.max_epipolar_px);
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
}

TEST(ParameterReaders, TheParameterFilesRestateTheStructDefaults) {
  // param_readers.test loads config/hull.yaml into /hull_yaml and config/matcher.yaml into
  // /matcher_yaml.
  ASSERT_TRUE(ros::param::has("/hull_yaml/depth"));
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
  const auto hull = [](const ros::NodeHandle& nh) {
    readHullNodeConfig(nh);
    readHullStreamConfig(nh);
  };
  const auto matcher = [](const ros::NodeHandle& nh) { readMatcherSettings(nh); };
  for (const auto& [ns, read] :
       {std::pair<std::string, std::function<void(const ros::NodeHandle&)>>("/hull_yaml", hull),
        {"/matcher_yaml", matcher}}) {
    XmlRpc::XmlRpcValue file;
    ASSERT_TRUE(ros::param::get(ns, file));
    ASSERT_EQ(file.getType(), XmlRpc::XmlRpcValue::TypeStruct);
    for (const auto& [key, value] : file) {
      EXPECT_TRUE(isRead(ns, key, read)) << ns << "/" << key << " is not read by any reader";
    }
  }
}

TEST(ParameterReaders, UnsetParametersGiveTheStructDefaults) {
  expectDefaultHull(ros::NodeHandle("/nothing_set"));
  expectDefaultMatcher(ros::NodeHandle("/nothing_set"));
}

TEST(ParameterReaders, SetParametersAreRead) {
  ros::NodeHandle nh("/set");
  nh.setParam("depth", 6);
  nh.setParam("box", std::vector<double>{-1, -2, -3, 1, 2, 3});
  nh.setParam("skip_views", std::vector<std::string>{"view_0003"});
  nh.setParam("min_view_distance_m", 0);  // an integer where a number is expected is fine
  nh.setParam("filters", std::vector<std::string>{"gsc", "magsac"});
  nh.setParam("max_descriptor_distance", 250.0);
  nh.setParam("image_transport", "compressed");
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
  EXPECT_THROW(readHullStreamConfig(hull_with("depth", 6.5)), std::invalid_argument);
  EXPECT_THROW(readHullStreamConfig(hull_with("min_view_angle_deg", -1.0)), std::invalid_argument);
  EXPECT_THROW(readHullNodeConfig(hull_with("from_image", std::string("yes"))),
               std::invalid_argument);
  EXPECT_THROW(readMatcherSettings(hull_with("filters", std::string("gsc"))),
               std::invalid_argument);
  EXPECT_THROW(readMatcherSettings(hull_with("ratio", std::string("0.8"))), std::invalid_argument);
  EXPECT_THROW(readHullNodeConfig(hull_with("queue_size", 0)), std::invalid_argument);
  EXPECT_THROW(readMatcherSettings(hull_with("max_waiting_pairs", -1)), std::invalid_argument);
  EXPECT_THROW(readMatcherSettings(hull_with("workers", 0)), std::invalid_argument);
}

}  // namespace
}  // namespace sift_hull

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_param_readers");
  ros::NodeHandle nh;
  return RUN_ALL_TESTS();
}
