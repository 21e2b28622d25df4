// Every filter setting tuned at run time, swept across its declared range on synthetic pairs (a 3D
// scene with its exact F, a similarity, two motions, each with 30 % mismatches): at every value,
// each filter that uses the setting keeps a share of the true matches on the pairs its defaults
// handle well. A value that keeps nothing there is a fault of the filter or of the range.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <string>
#include <vector>

#include "sift_hull/eval/match_evaluation.h"
#include "sift_hull/features/labelled_matches.h"
#include "sift_hull/filters/filter.h"
#include "synthetic_putatives.h"
#include "two_view_scene.h"

namespace sift_hull {
namespace {

/// A setting, the filters that use it and the values swept: the first and last are the ends of
/// its declared range (for a range open at 0, the first is the smallest value anyone would set;
// for one open above, the last is far beyond any use).
struct Sweep {
  std::string setting;
  std::vector<std::string> filters;
  std::vector<double> values;
};

const std::vector<Sweep>& sweeps() {
  static const std::vector<Sweep> all = {
      {"epipolar_max_distance_px", {"epipolar"}, {0.1, 0.5, 2, 10, 50, 100}},
      {"gsc_max_histogram_distance", {"gsc"}, {0.1, 0.2, 0.5, 1, 1.5}},
      {"ransac_max_epipolar_px", {"ransac"}, {0.1, 0.5, 1, 5, 20, 100}},
      {"magsac_max_epipolar_px",
       {"magsac", "guided", "vote_ransac"},
       {0.1, 0.5, 1, 5, 20, 42, 100}},
      {"gms_threshold_factor", {"gms"}, {0.1, 1, 3, 6, 12}},
      {"lsc_max_relative_error", {"lsc", "guided"}, {0.2, 0.35, 0.7, 1, 1.5, 2}},
      {"lsc_min_support", {"lsc", "guided"}, {0, 0.1, 0.2, 0.25, 0.3}},
      {"local_gsc_max_histogram_distance", {"local_gsc"}, {0.2, 0.35, 0.7, 1, 1.5}},
      {"guided_max_transfer_px", {"guided", "vote_ransac"}, {0.1, 0.5, 3, 10, 30, 100}},
      {"guided_min_support", {"guided"}, {0, 0.1, 0.2, 0.25, 0.3}},
      {"vote_ransac_max_angle_deg", {"vote_ransac"}, {0.5, 5, 15, 30, 45, 60}},
      {"vote_ransac_max_scale_ratio", {"vote_ransac"}, {1.01, 1.1, 1.5, 2, 4, 16, 1000}},
  };
  return all;
}

struct NamedPair {
  std::string name;
  LabelledMatches matches;
};

const std::vector<NamedPair>& pairs() {
  static const std::vector<NamedPair> all = [] {
    NamedPair scene{"scene", test::sceneMatches(600, 0.3, 71, 0.3)};
    scene.matches.putative.F_right_left = test::twoCameras().F();
    return std::vector<NamedPair>{
        scene, {"similarity", test::synthetic(0.3, 73)}, {"two motions", test::twoMotions()}};
  }();
  return all;
}

double recallOf(const std::string& filter, const FilterConfigs& configs, const NamedPair& pair) {
  if (filter == "epipolar" && !pair.matches.putative.F_right_left) return -1.0;
  const FilterResult result = makeFilter(filter, configs)->apply(pair.matches.putative);
  return scoreFilter(pair.matches.truth, result).recall();
}

TEST(FilterRanges, EveryRuntimeSettingIsSweptOverItsWholeRange) {
  const SettingTable<FilterConfigs>& table = settingsOf<FilterConfigs>();
  size_t runtime = 0;
  for (const Setting<FilterConfigs>& s : table.settings()) runtime += s.info.runtime;
  EXPECT_EQ(runtime, sweeps().size());
  for (const Sweep& sweep : sweeps()) {
    const Setting<FilterConfigs>* s = table.find(sweep.setting);
    ASSERT_NE(s, nullptr) << sweep.setting;
    EXPECT_TRUE(s->info.runtime) << sweep.setting;
    if (std::isinf(s->info.max)) {  // open above: far beyond any use
      EXPECT_GE(sweep.values.back(), 1000.0) << sweep.setting;
    } else {
      EXPECT_EQ(sweep.values.back(), s->info.max) << sweep.setting;
    }
    if (s->info.min_exclusive) {
      EXPECT_GT(sweep.values.front(), s->info.min) << sweep.setting;
    } else {
      EXPECT_EQ(sweep.values.front(), s->info.min) << sweep.setting;
    }
    for (double v : sweep.values) {
      FilterConfigs configs;
      s->set(&configs, v);
      EXPECT_NO_THROW(validate(configs)) << sweep.setting << " " << v;
    }
  }
}

/// A filter at any value keeps at least this share of the true matches of a pair on which its
/// defaults keep most of them (kHandledWell).
constexpr double kMinRecall = 0.1;
constexpr double kHandledWell = 0.8;

TEST(FilterRanges, EveryValueKeepsAShareOfTheTrueMatches) {
  for (const Sweep& sweep : sweeps()) {
    const Setting<FilterConfigs>* s = settingsOf<FilterConfigs>().find(sweep.setting);
    ASSERT_NE(s, nullptr) << sweep.setting;
    for (const std::string& filter : sweep.filters) {
      for (const NamedPair& pair : pairs()) {
        const double by_default = recallOf(filter, FilterConfigs(), pair);
        if (!(by_default >= kHandledWell)) continue;
        std::cout << sweep.setting << ", " << filter << ", " << pair.name << ":";
        for (double v : sweep.values) {
          FilterConfigs configs;
          s->set(&configs, v);
          const double recall = recallOf(filter, configs, pair);
          std::cout << " " << v << ": " << recall;
          EXPECT_GE(recall, kMinRecall) << sweep.setting << " " << v << ", " << filter << ", "
                                        << pair.name;
        }
        std::cout << "\n";
      }
    }
  }
}

}  // namespace
}  // namespace sift_hull
