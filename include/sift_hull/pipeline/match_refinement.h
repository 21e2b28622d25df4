#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <opencv2/core.hpp>
#include <utility>
#include <vector>

#include "sift_hull/features/feature_cache.h"
#include "sift_hull/filters/filter.h"
#include "sift_hull/geometry/camera.h"
#include "sift_hull/hull/octree.h"
#include "sift_hull/pipeline/pair_pipeline.h"
#include "sift_hull/refine/dense_matching.h"
#include "sift_hull/refine/free_space.h"
#include "sift_hull/refine/surface_points.h"

namespace sift_hull {

/// Which pairs of views the matches refinement matches.
enum class ViewPairing {
  kNeighbours,  ///< each view with its kPairingNeighbours nearest (camera centres)
  kAll,         ///< every pair
};

/// Views each view pairs with under ViewPairing::kNeighbours.
constexpr size_t kPairingNeighbours = 2;

/// How the matches refinement pairs, matches and keeps: the existing configs of its stages.
struct MatchRefineConfig {
  ViewPairing pairing = ViewPairing::kNeighbours;
  /// SIFT (a lower contrast threshold gives denser points), the ratio test and the guided
  /// matching along the epipolar lines (epipolar_search_px, 2 px by default).
  PairPipelineConfig pair = [] {
    PairPipelineConfig config;
    config.epipolar_search_px = 2.0;
    return config;
  }();
  DenseMatchConfig dense;  ///< off unless grid_step_px > 0
  SurfacePointConfig points;
  FreeSpaceConfig free_space;
};

/// Throws std::invalid_argument naming the first bad field of any stage's config.
void validate(const MatchRefineConfig& config);

/// The calibrated views the refinement reads, each image loaded when first needed (a view that
/// no pair holds is never read).
struct RefineViews {
  std::vector<PinholeCamera> cameras;  ///< raw pixels of the images; the hull's frame
  /// View i's 8-bit image (grey or BGR), of the size its camera was calibrated for.
  std::function<cv::Mat(uint32_t)> image;
  /// View i's silhouette (CV_8UC1, non-zero inside), for dense matching only.
  std::function<cv::Mat(uint32_t)> mask;
};

/// Wall-clock times of the refinement's stages, milliseconds.
struct MatchRefineTimes {
  double matching = 0.0;     ///< images, SIFT, matching, filtering, dense matching
  double points = 0.0;       ///< surfacePoints
  double free_voxels = 0.0;  ///< freeVoxels
};

/// What the matches give the hull.
struct MatchRefineResult {
  std::vector<std::pair<uint32_t, uint32_t>> view_pairs;  ///< (a, b), a < b, ascending
  /// Each pair's kept SIFT matches (with keypoint ids), in view_pairs' order, then each pair's
  /// dense matches (without keypoint ids) when dense matching is on.
  std::vector<PairMatches> pairs;
  size_t sift_matches = 0, dense_matches = 0;
  std::vector<SurfacePoint> points;  ///< the consistent surface points (surfacePoints), metres
  SurfacePointCounts counts;
  /// The finest voxels the lines of sight to the points make free (freeVoxels), for
  /// VisualHull::carveFree.
  std::vector<Eigen::Vector3i> free_voxels;
  MatchRefineTimes times_ms;
};

/// The pairs the refinement matches: (a, b) with a < b, ascending; with kNeighbours each view
/// with its kPairingNeighbours nearest by camera centre, with kAll every pair.
std::vector<std::pair<uint32_t, uint32_t>> refinementViewPairs(
    const std::vector<PinholeCamera>& cameras, ViewPairing pairing);

/// The surface points of matched pairs and the free space they show: surfacePoints (consistent
/// points of `pairs`, whose view indices index `cameras`), then freeVoxels of the hull. Usable
/// on its own by a caller with its own matches. Fills `result`'s points, counts, free_voxels
/// and the points and free_voxels times. Throws std::invalid_argument for a bad config or a view
/// index beyond `cameras`.
void surfacePointsAndFreeSpace(const std::vector<PinholeCamera>& cameras,
                               const std::vector<PairMatches>& pairs, const VisualHull& hull,
                               const MatchRefineConfig& config, MatchRefineResult* result);

/// The matches refinement of a hull: the chosen pairs of views run through runPair (SIFT of each
/// view once and one view at a time, through `cache` when given, else a cache of its own holding
/// every view; guided matching along the epipolar lines; `filter`'s kept matches), dense
/// matching inside the hull when configured (on the hull's threads), then
/// surfacePointsAndFreeSpace. The hull is not
/// changed: carve with `VisualHull::carveFree(result.free_voxels)`. Throws std::invalid_argument
/// for a bad config or a missing image function (a missing mask function only with dense
/// matching on); what the image and mask functions throw passes through. Fewer than two cameras
/// give no pair and nothing to carve.
MatchRefineResult refineWithMatches(const RefineViews& views, const VisualHull& hull,
                                    const MatchFilter& filter, const MatchRefineConfig& config,
                                    FeatureCache* cache = nullptr);

}  // namespace sift_hull
