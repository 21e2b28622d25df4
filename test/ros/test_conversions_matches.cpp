// The matcher's message conversions without a ROS master: keypoints, the correspondences with
// each filter's decision, and their refusals.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "lib/conversions.h"

namespace sift_hull {
namespace {

/// Three matches: left keypoint i with right keypoint 2 - i.
PutativeMatches threeMatches() {
  PutativeMatches matches;
  for (int i = 0; i < 3; ++i) {
    matches.left_keypoints.emplace_back(cv::Point2f(10.0f * i, 5.0f), 2.0f + i, 30.0f * i, 0.5f * i,
                                        i);
    matches.right_keypoints.emplace_back(cv::Point2f(100.0f + i, 7.0f), 3.0f, 45.0f);
  }
  for (int i = 0; i < 3; ++i) matches.matches.emplace_back(i, 2 - i, 0.25f * (i + 1));
  return matches;
}

FilterResult result(std::vector<uint8_t> keep, std::vector<double> score) {
  return FilterResult{std::move(keep), std::move(score)};
}

std_msgs::Header header(const std::string& frame, double seconds) {
  std_msgs::Header h;
  h.frame_id = frame;
  h.stamp = ros::Time(seconds);
  return h;
}

TEST(KeypointMessage, CopiesEveryField) {
  const cv::KeyPoint keypoint(cv::Point2f(12.5f, -3.25f), 7.0f, 123.0f, 0.875f, 3);
  const sift_hull::Keypoint message = ros_conversions::keypointMessage(keypoint);
  EXPECT_FLOAT_EQ(message.x, 12.5f);
  EXPECT_FLOAT_EQ(message.y, -3.25f);
  EXPECT_FLOAT_EQ(message.size, 7.0f);
  EXPECT_FLOAT_EQ(message.angle, 123.0f);
  EXPECT_FLOAT_EQ(message.response, 0.875f);
  EXPECT_EQ(message.octave, 3);
}

TEST(CorrespondencesMessage, EachMatchCarriesItsKeypointsAndABitPerFilterThatKeptIt) {
  const PutativeMatches matches = threeMatches();
  const std::vector<FilterResult> results = {result({1, 0, 1}, {0.1, 0.9, 0.2}),
                                             result({1, 1, 0}, {0.05, 0.15, 0.6})};
  const sift_hull::Correspondences out =
      ros_conversions::correspondencesMessage(header("left", 2.0), header("right", 2.5),
                                              {"epipolar", "gsc"}, "{\"x\":1}", matches, results);
  EXPECT_EQ(out.header.frame_id, "left");
  EXPECT_EQ(out.header.stamp, ros::Time(2.0));
  EXPECT_EQ(out.right_header.frame_id, "right");
  EXPECT_EQ(out.right_header.stamp, ros::Time(2.5));
  EXPECT_EQ(out.filters, (std::vector<std::string>{"epipolar", "gsc"}));
  EXPECT_EQ(out.filter_settings, "{\"x\":1}");
  ASSERT_EQ(out.matches.size(), 3u);
  const std::vector<uint32_t> kept_by = {0b11, 0b10, 0b01};
  for (size_t m = 0; m < 3; ++m) {
    const sift_hull::Correspondence& c = out.matches[m];
    EXPECT_FLOAT_EQ(c.left.x, 10.0f * m) << m;
    EXPECT_FLOAT_EQ(c.left.size, 2.0f + m) << m;
    EXPECT_EQ(c.left.octave, static_cast<int>(m)) << m;
    EXPECT_FLOAT_EQ(c.right.x, 100.0f + (2 - m)) << m;  // right keypoint 2 - m
    EXPECT_FLOAT_EQ(c.descriptor_distance, 0.25f * (m + 1)) << m;
    EXPECT_FLOAT_EQ(c.gsc_score, results[1].score[m]) << m;  // the filter named gsc
    EXPECT_EQ(c.kept_by, kept_by[m]) << m;
  }
}

TEST(CorrespondencesMessage, WithoutAGscFilterTheScoreIsNan) {
  const sift_hull::Correspondences out =
      ros_conversions::correspondencesMessage(header("l", 1.0), header("r", 1.0), {"ransac"}, "{}",
                                              threeMatches(), {result({0, 0, 1}, {1.0, 2.0, 3.0})});
  ASSERT_EQ(out.matches.size(), 3u);
  for (const sift_hull::Correspondence& c : out.matches) EXPECT_TRUE(std::isnan(c.gsc_score));
  EXPECT_EQ(out.matches[2].kept_by, 1u);
  EXPECT_EQ(out.matches[0].kept_by, 0u);
}

TEST(CorrespondencesMessage, RefusesResultsThatDoNotFitTheMatchesOrTheNames) {
  const PutativeMatches matches = threeMatches();
  const FilterResult good = result({1, 1, 1}, {0.0, 0.0, 0.0});
  EXPECT_THROW(ros_conversions::correspondencesMessage(header("l", 1), header("r", 1), {"a", "b"},
                                                       "{}", matches, {good}),
               std::invalid_argument);
  EXPECT_THROW(ros_conversions::correspondencesMessage(header("l", 1), header("r", 1), {"a"}, "{}",
                                                       matches, {result({1, 1}, {0.0, 0.0})}),
               std::invalid_argument);
  const std::vector<std::string> names(33, "ratio");
  EXPECT_THROW(
      ros_conversions::correspondencesMessage(header("l", 1), header("r", 1), names, "{}", matches,
                                              std::vector<FilterResult>(33, good)),
      std::invalid_argument);
  EXPECT_NO_THROW(ros_conversions::correspondencesMessage(header("l", 1), header("r", 1), {"a"},
                                                          "{}", matches, {good}));
}

TEST(SettingsJson, HoldsEverySettingUnderItsParameterName) {
  MatchConfig matching;
  matching.ratio = 0.7;
  matching.max_descriptor_distance = 250.0;
  FilterConfigs filters;
  filters.epipolar.max_distance_px = 1.5;
  filters.gsc.max_histogram_distance = 0.25;
  filters.ransac.max_epipolar_px = 0.75;
  filters.magsac.max_iterations = 500;
  filters.gms.grid_cells = 12;
  const nlohmann::json json =
      nlohmann::json::parse(ros_conversions::settingsJson(matching, filters));
  EXPECT_DOUBLE_EQ(json.at("ratio").get<double>(), 0.7);
  EXPECT_DOUBLE_EQ(json.at("max_descriptor_distance").get<double>(), 250.0);
  EXPECT_DOUBLE_EQ(json.at("epipolar_max_distance_px").get<double>(), 1.5);
  EXPECT_DOUBLE_EQ(json.at("gsc_max_histogram_distance").get<double>(), 0.25);
  EXPECT_DOUBLE_EQ(json.at("ransac_max_epipolar_px").get<double>(), 0.75);
  EXPECT_DOUBLE_EQ(json.at("magsac_max_epipolar_px").get<double>(), filters.magsac.max_epipolar_px);
  EXPECT_EQ(json.at("magsac_max_iterations").get<int>(), 500);
  EXPECT_EQ(json.at("gms_grid_cells").get<int>(), 12);
  // Each key is the name of a parameter that config/matcher.yaml states (one name per setting).
  std::ifstream yaml(std::string(SIFT_HULL_SOURCE_DIR) + "/config/matcher.yaml");
  ASSERT_TRUE(yaml.good());
  std::set<std::string> parameters;
  for (std::string line; std::getline(yaml, line);) {
    const size_t colon = line.find(':');
    if (line.empty() || line[0] == '#' || line[0] == ' ' || colon == std::string::npos) continue;
    parameters.insert(line.substr(0, colon));
  }
  ASSERT_GT(parameters.size(), 20u);
  for (const auto& [key, value] : json.items()) {
    EXPECT_TRUE(parameters.count(key)) << key << " is no parameter of config/matcher.yaml";
  }
  EXPECT_GE(json.size(), 16u);
  // No limit on the descriptor distance is null, not infinity (which JSON cannot hold).
  matching.max_descriptor_distance = INFINITY;
  EXPECT_TRUE(nlohmann::json::parse(ros_conversions::settingsJson(matching, filters))
                  .at("max_descriptor_distance")
                  .is_null());
}

}  // namespace
}  // namespace sift_hull
