#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "sift_hull/features/feature_cache.h"
#include "sift_hull/features/matching.h"
#include "sift_hull/features/sift.h"
#include "sift_hull/filters/filter.h"
#include "sift_hull/filters/filter_result.h"
#include "sift_hull/geometry/camera.h"
#include "sift_hull/refine/surface_points.h"
#include "sift_hull/settings.h"

namespace sift_hull {

/// How a pair of images becomes putative matches: SIFT, then nearest neighbours of the
/// descriptors. The filters are not part of it (they are given to runPair, built by makeFilter
/// from FilterConfigs), so that a caller that keeps its filters (the matcher node) builds them
/// once.
struct PairPipelineConfig {
  SiftConfig sift;
  MatchConfig matching;
  /// 0: every left descriptor is matched against every right one (matchFeatures). Greater than 0,
  /// and the pair has cameras: guided matching within this many pixels of the epipolar lines
  /// (matchAlongEpipolarLines; MatchConfig's cross_check and backend do not apply).
  double epipolar_search_px = 0.0;
};
/// Its settings: SIFT's and the matching's under their own names, then epipolar_search_px.
template <>
const SettingTable<PairPipelineConfig>& settingsOf<PairPipelineConfig>();

/// Throws std::invalid_argument naming the first bad field.
void validate(const PairPipelineConfig& config);

/// One pair of images and what is known of their geometry.
struct PairInput {
  cv::Mat left_image, right_image;  ///< 8-bit, grey or BGR (what detectSift takes)
  /// The pair's cameras (left, right), raw pixels of these images: the putative matches are
  /// calibrated (calibratePair) and the first filter's kept matches triangulated.
  std::optional<std::pair<PinholeCamera, PinholeCamera>> cameras;
  /// Without cameras, a fundamental matrix x_r^T F x_l = 0 to calibrate with (a rectified pair:
  /// rectifiedFundamentalMatrix()); nothing is triangulated then. Ignored when cameras are given.
  std::optional<Eigen::Matrix3d> F_right_left;
  uint32_t left_view = 0, right_view = 1;  ///< the view indices written into PairResult::kept
  /// A pair with fewer keypoints in either image is not filtered (PairResult::why_not); 0 filters
  /// every pair, however few its matches.
  size_t min_keypoints = 2;
};

/// One filter's verdicts on the putative matches and its wall-clock time.
struct FilterVerdicts {
  std::string name;  ///< MatchFilter::name()
  FilterResult result;
  double time_ms = 0.0;
};

/// Wall-clock times of runPair's stages, milliseconds. Each image's SIFT is timed on its own
/// thread (the two run at once); a feature cache hit takes about nothing.
struct PairTimes {
  double sift_left_ms = 0.0, sift_right_ms = 0.0, matching_ms = 0.0, triangulation_ms = 0.0;
};

/// What runPair found.
struct PairResult {
  /// Set when the pair was not filtered: an image has fewer than PairInput::min_keypoints
  /// keypoints. `putative` is then as matched, and verdicts, kept and surface_points are empty.
  std::string why_not;
  PutativeMatches putative;  ///< both keypoint sets, the matches, F and cameras when calibrated
  std::vector<FilterVerdicts> verdicts;  ///< one per filter, in the order given
  /// The first filter's kept matches with their keypoint ids (left_view, right_view of the input).
  PairMatches kept;
  /// With cameras: `kept` triangulated once (triangulatePair: DLT on ideal pixels, in the
  /// cameras' frame, metres), each with its reprojection error and depth sigma; matches at
  /// infinity or behind a camera are left out.
  std::vector<SurfacePoint> surface_points;
  PairTimes times;
};

/// Describes both images (SIFT; the right one on a second thread; through `cache` when one is
/// given, keyed by imageKey, so that an image in several pairs is described once), matches them
/// (PairPipelineConfig), calibrates the putative matches with the cameras or F, runs every filter
/// on them and triangulates the first filter's kept matches when cameras are given. Throws
/// std::invalid_argument for a bad config, no filter, a null filter, an empty image or one over
/// SiftConfig::max_image_pixels; whatever a filter throws passes through.
PairResult runPair(const PairInput& input, const PairPipelineConfig& config,
                   const std::vector<const MatchFilter*>& filters, FeatureCache* cache = nullptr);

/// An image's SIFT features as runPair takes them: through `cache` (keyed by imageKey) when one
/// is given, else detectSift. A caller that wants one SIFT at a time (bounded memory, as the
/// matches refinement) describes both images with it before runPair, which then finds them in
/// the cache. Throws as detectSift.
std::shared_ptr<const Features> describeImage(const cv::Mat& image, const SiftConfig& sift,
                                              FeatureCache* cache);

/// The matches that `kept` keeps (one flag per putative match), as PairMatches of views
/// left_view and right_view with their raw pixels and keypoint ids. Throws std::invalid_argument
/// when `kept` has not one flag per match.
PairMatches keptPairMatches(const PutativeMatches& putative, const std::vector<uint8_t>& kept,
                            uint32_t left_view, uint32_t right_view);

/// The raw filters of `filters` as runPair takes them.
std::vector<const MatchFilter*> filterPointers(
    const std::vector<std::unique_ptr<MatchFilter>>& filters);

}  // namespace sift_hull
