// The settings tables of the filters' config structs (sift_hull/settings.h), and the range checks
// that derive from them.

#include <string>

#include "sift_hull/filters/filter.h"
#include "sift_hull/limits.h"

namespace sift_hull {
namespace {

/// Widest threshold in pixels any filter takes. The evaluation pairs are 375 to 800 px across: at
/// 1000 px every putative is an inlier of any F or H, so MAGSAC and the epipolar check kept all of
/// them, and vote_ransac, whose fit no longer truncated any residual, found no motion better than
/// chance and kept none of a pair it handles at its defaults. 100 px still filters there.
constexpr double kMaxPixels = 100.0;
constexpr int kMaxNeighbours = 1024;  ///< lsc and local_gsc look at no more neighbours
constexpr int kMaxSamples = 1000000;  ///< largest fit set or sample

}  // namespace

template <>
const SettingTable<EpipolarConfig>& settingsOf<EpipolarConfig>() {
  static const SettingTable<EpipolarConfig> table = [] {
    SettingTable<EpipolarConfig> t;
    t.add("max_distance_px", &EpipolarConfig::max_distance_px, "px",
          "epipolar filter: largest distance of a point to the other's epipolar line")
        .above(0.0, kMaxPixels)
        .tunedAtRunTime();
    return t;
  }();
  return table;
}

template <>
const SettingTable<GscConfig>& settingsOf<GscConfig>() {
  static const SettingTable<GscConfig> table = [] {
    SettingTable<GscConfig> t;
    t.add("max_histogram_distance", &GscConfig::max_histogram_distance, "",
          "GSC: largest distance between the left and right polar-angle histograms kept (at most "
          "sqrt(2))")
        // Below 0.1 no evaluation pair with perspective keeps a share of its correct matches
        // (graf 1-3 at 0.05: 3 of 392; at 0: none anywhere, histograms are never equal).
        .range(0.1, 1.5)
        .tunedAtRunTime();
    t.add("threads", &GscConfig::threads, "", "GSC threads; 0: all hardware threads")
        .range(0, limits::kMaxThreads);
    t.add("max_support", &GscConfig::max_support, "matches",
          "GSC histograms over this many sampled matches; 0: all (the exact filter)")
        .range(0, kMaxSamples);
    return t;
  }();
  return table;
}

template <>
const SettingTable<RobustFitConfig>& settingsOf<RobustFitConfig>() {
  static const SettingTable<RobustFitConfig> table = [] {
    SettingTable<RobustFitConfig> t;
    t.add("max_epipolar_px", &RobustFitConfig::max_epipolar_px, "px",
          "largest point-to-epipolar-line distance of an inlier of F")
        .above(0.0, kMaxPixels)
        .tunedAtRunTime();
    t.add("confidence", &RobustFitConfig::confidence, "",
          "probability of having drawn one clean sample when the search stops")
        .between(0.0, 1.0);
    t.add("max_iterations", &RobustFitConfig::max_iterations, "", "samples drawn at most")
        .range(1, kMaxSamples);
    t.add("seed", &RobustFitConfig::seed, "",
          "the sampler's random state: the same seed, the same answer");
    return t;
  }();
  return table;
}

template <>
const SettingTable<GmsConfig>& settingsOf<GmsConfig>() {
  static const SettingTable<GmsConfig> table = [] {
    SettingTable<GmsConfig> t;
    t.add("grid_cells", &GmsConfig::grid_cells, "", "GMS cells per image side")
        .range(3, limits::kMaxGmsGridCells);
    t.add("threshold_factor", &GmsConfig::threshold_factor, "",
          "GMS: alpha in the cell-pair threshold alpha sqrt(n)")
        // A cell pair's score is at most the 9 cells' matches, 9 n, so alpha sqrt(n) is passed
        // only where n > (alpha / 9)^2: 1.8 matches a cell at 12 (twice the paper's 6), what
        // SIFT's hundreds of putatives give on 20x20 cells where they are dense; at 25 every
        // evaluation pair but one kept nothing (a synthetic scene with 600 putatives: none at 20).
        .above(0.0, 12.0)
        .tunedAtRunTime();
    t.add("with_rotation", &GmsConfig::with_rotation, "",
          "GMS: also try the 8 rotations of the 3x3 neighbourhood");
    t.add("with_scale", &GmsConfig::with_scale, "",
          "GMS: also try 5 relative grid scales of the right image");
    return t;
  }();
  return table;
}

template <>
const SettingTable<LscConfig>& settingsOf<LscConfig>() {
  static const SettingTable<LscConfig> table = [] {
    SettingTable<LscConfig> t;
    t.add("neighbours", &LscConfig::neighbours, "matches",
          "lsc: nearest matches looked at in each image")
        .range(1, kMaxNeighbours);
    t.add("max_relative_error", &LscConfig::max_relative_error, "",
          "lsc (and guided): tolerance of a neighbour's predicted position, as a share of its "
          "distance")
        // SIFT's scale and orientation and a view's perspective put correct neighbours tens of
        // percent off a similarity's prediction: below 0.2, lsc kept too few of graf 1-4 for
        // guided to fit its motion to (guided kept nothing there; at 0.2, half its correct).
        .range(0.2, 2.0)
        .tunedAtRunTime();
    t.add("min_tolerance_px", &LscConfig::min_tolerance_px, "px", "lsc: tolerance floor")
        .atLeast(0.0);
    t.add("min_support", &LscConfig::min_support, "",
          "lsc: share of the nearest matches that must agree with a match")
        // Mismatches do not agree: a correct match's support is at most the share of correct
        // matches around it, a third on graf 1-4 (75 of 231). Above 0.3 guided kept nothing
        // there (too few lsc survivors to fit to); at 0.75 and more lsc kept next to nothing of
        // a synthetic scene with 30 % mismatches.
        .range(0.0, 0.3)
        .tunedAtRunTime();
    return t;
  }();
  return table;
}

template <>
const SettingTable<LocalGscConfig>& settingsOf<LocalGscConfig>() {
  static const SettingTable<LocalGscConfig> table = [] {
    SettingTable<LocalGscConfig> t;
    t.add("neighbours", &LocalGscConfig::neighbours, "matches",
          "local_gsc: nearest matches in each image")
        .range(1, kMaxNeighbours);
    t.add("max_histogram_distance", &LocalGscConfig::max_histogram_distance, "",
          "local_gsc: largest distance between the local polar-angle histograms kept (at most "
          "sqrt(2))")
        // Over some 30 neighbours, each mismatch among them moves the distance by up to
        // sqrt(2) / 30: below 0.2 only neighbourhoods almost free of mismatches pass (at 0.1, 2
        // to 5 % of a synthetic pair's correct matches with 30 % mismatches; none of graf 1-4).
        .range(0.2, 1.5)
        .tunedAtRunTime();
    return t;
  }();
  return table;
}

template <>
const SettingTable<GuidedConfig>& settingsOf<GuidedConfig>() {
  static const SettingTable<GuidedConfig> table = [] {
    SettingTable<GuidedConfig> t;
    t.add("max_transfer_px", &GuidedConfig::max_transfer_px, "px",
          "guided and vote_ransac (best): largest homography transfer error of an inlier, both "
          "ways")
        .above(0.0, kMaxPixels)
        .tunedAtRunTime();
    t.add("homography_share", &GuidedConfig::homography_share, "",
          "guided and vote_ransac: a homography is taken when it explains this share of F's "
          "inliers")
        .range(0.0, 10.0);
    t.add("max_models", &GuidedConfig::max_models, "", "guided and vote_ransac: motions looked for")
        .range(1, 8);
    t.add("min_model_inliers", &GuidedConfig::min_model_inliers, "matches",
          "guided and vote_ransac: inliers a motion needs")
        .range(8, kMaxSamples);
    t.add("min_support", &GuidedConfig::min_support, "",
          "guided: lsc support a match the model explains still needs")
        // At most the share of correct matches around a match, as lsc_min_support: at 0.5
        // guided kept 4 of graf 1-4's 75 correct (at its default 0.1: 67).
        .range(0.0, 0.3)
        .tunedAtRunTime();
    t.add("max_fit_points", &GuidedConfig::max_fit_points, "matches",
          "guided: lsc survivors MAGSAC fits to (a random sample)")
        .range(16, kMaxSamples);
    t.add("tolerance_scale", &GuidedConfig::tolerance_scale, "",
          "guided and vote_ransac (best): the final verdict's unit in each image: pixels; model, "
          "the homography's local scale (at least 1); keypoints, the keypoint's SIFT octave "
          "interval (size / 3.2, at least 1)")
        .oneOf({"pixels", "model", "keypoints"});
    return t;
  }();
  return table;
}

template <>
const SettingTable<VoteRansacConfig>& settingsOf<VoteRansacConfig>() {
  static const SettingTable<VoteRansacConfig> table = [] {
    SettingTable<VoteRansacConfig> t;
    t.add("max_angle_deg", &VoteRansacConfig::max_angle_deg, "deg",
          "vote_ransac (best): half width of the rotation vote's window, which chooses where "
          "samples are drawn; at most 60: a further motion is looked for only where the window "
          "holds twice the share of evenly spread rotations, which a wider one cannot once half "
          "the matches left are mismatches")
        .above(0.0, 60.0)
        .tunedAtRunTime();
    t.add("max_scale_ratio", &VoteRansacConfig::max_scale_ratio, "",
          "vote_ransac (best): half width of the scale vote's window, as a factor")
        .above(1.0)
        .tunedAtRunTime();
    t.add("max_fit_points", &VoteRansacConfig::max_fit_points, "matches",
          "vote_ransac (best): putatives the motions are fitted to (a random sample)")
        .range(16, kMaxSamples);
    return t;
  }();
  return table;
}

template <>
const SettingTable<FilterConfigs>& settingsOf<FilterConfigs>() {
  static const SettingTable<FilterConfigs> table = [] {
    SettingTable<FilterConfigs> t;
    t.nest("epipolar", &FilterConfigs::epipolar, settingsOf<EpipolarConfig>());
    t.nest("gsc", &FilterConfigs::gsc, settingsOf<GscConfig>());
    t.nest("ransac", &FilterConfigs::ransac, settingsOf<RobustFitConfig>());
    t.nest("magsac", &FilterConfigs::magsac, settingsOf<RobustFitConfig>());
    t.nest("gms", &FilterConfigs::gms, settingsOf<GmsConfig>());
    t.nest("lsc", &FilterConfigs::lsc, settingsOf<LscConfig>());
    t.nest("local_gsc", &FilterConfigs::local_gsc, settingsOf<LocalGscConfig>());
    t.nest("guided", &FilterConfigs::guided, settingsOf<GuidedConfig>());
    t.nest("vote_ransac", &FilterConfigs::vote_ransac, settingsOf<VoteRansacConfig>());
    return t;
  }();
  return table;
}

void validate(const FilterConfigs& configs) { checkSettings(configs, "filter config"); }

void validate(const GmsConfig& config) { checkSettings(config, "GmsConfig"); }

void validate(const LscConfig& config) { checkSettings(config, "filter config: lsc"); }

void validate(const LocalGscConfig& config) { checkSettings(config, "filter config: local_gsc"); }

void validate(const GuidedConfig& config) { checkSettings(config, "filter config: guided"); }

void validate(const VoteRansacConfig& config) {
  checkSettings(config, "filter config: vote_ransac");
}

void validate(const RobustFitConfig& config, const std::string& name) {
  checkSettings(config, "filter config: " + name);
}

}  // namespace sift_hull
