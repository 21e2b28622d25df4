// The run-time thresholds of cfg/Matcher.cfg start where the config structs do: one default for
// each setting.

#include <gtest/gtest.h>

#include "sift_hull/MatcherConfig.h"
#include "sift_hull/features/matching.h"
#include "sift_hull/filters/filter.h"

namespace sift_hull {
namespace {

TEST(MatcherReconfigure, DefaultsEqualTheConfigStructs) {
  const MatcherConfig& cfg = MatcherConfig::__getDefault__();
  const MatchConfig matching;
  const FilterConfigs filters;
  EXPECT_EQ(cfg.ratio, matching.ratio);
  EXPECT_FALSE(std::isfinite(matching.max_descriptor_distance));
  EXPECT_EQ(cfg.max_descriptor_distance, 0.0);  // 0 stands for no limit
  EXPECT_EQ(cfg.cross_check, matching.cross_check);
  EXPECT_EQ(cfg.max_histogram_distance, filters.gsc.max_histogram_distance);
  EXPECT_EQ(cfg.ransac_max_epipolar_px, filters.ransac.max_epipolar_px);
  EXPECT_EQ(cfg.magsac_max_epipolar_px, filters.magsac.max_epipolar_px);
  EXPECT_EQ(cfg.max_epipolar_px, filters.epipolar.max_epipolar_px);
  EXPECT_EQ(cfg.threshold_factor, filters.gms.threshold_factor);
  EXPECT_EQ(cfg.guided_max_transfer_px, filters.guided.guided_max_transfer_px);
  EXPECT_EQ(cfg.guided_min_support, filters.guided.guided_min_support);
  EXPECT_EQ(cfg.lsc_max_relative_error, filters.lsc.lsc_max_relative_error);
  EXPECT_EQ(cfg.lsc_min_support, filters.lsc.lsc_min_support);
  EXPECT_EQ(cfg.vote_ransac_max_angle_deg, filters.vote_ransac.vote_ransac_max_angle_deg);
  EXPECT_EQ(cfg.vote_ransac_max_scale_ratio, filters.vote_ransac.vote_ransac_max_scale_ratio);
}

}  // namespace
}  // namespace sift_hull
