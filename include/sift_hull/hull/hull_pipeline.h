#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "sift_hull/geometry/camera.h"
#include "sift_hull/hull/bounding_box.h"
#include "sift_hull/hull/hull_view.h"
#include "sift_hull/hull/mesh.h"
#include "sift_hull/hull/octree.h"
#include "sift_hull/hull/run_length_mask.h"

namespace sift_hull {

/// Calibrated silhouettes, one entry per view in each vector.
struct HullInput {
  std::vector<std::string> names;
  std::vector<PinholeCamera> cameras;
  std::vector<cv::Mat> masks;  ///< CV_8UC1, non-zero inside
  /// The silhouettes run-length encoded, used when `masks` is empty (loadHullInput gives these,
  /// so that no full-resolution mask stays in memory).
  std::vector<RunLengthMask> run_length_masks;
  /// Reduced loading (loadReducedHullInput): each view's reduction (its mask and camera are those
  /// of its image reduced so many times) and its image's full size. Empty: every view at full
  /// resolution, its image the size of its mask.
  std::vector<int> reductions;
  std::vector<cv::Size> image_sizes;
  /// View `view`'s reduction (1 without reduced loading).
  int reduction(size_t view) const { return reductions.empty() ? 1 : reductions.at(view); }

  /// Number of views: of `masks`, else of `run_length_masks`.
  size_t viewCount() const { return masks.empty() ? run_length_masks.size() : masks.size(); }
  /// View `view`'s silhouette: from `masks`, else decoded from `run_length_masks`.
  cv::Mat mask(size_t view) const {
    return masks.empty() ? run_length_masks.at(view).decode() : masks.at(view);
  }
};

/// Wall-clock times of the stages of buildHull, in milliseconds: the masks' run-length encoding
/// and 2-D bounds, the bounding box, the distance maps, carving, marching cubes, and all of them.
struct HullTimings {
  double distance_ms = 0.0, bbox_ms = 0.0, octree_ms = 0.0, mesh_ms = 0.0, total_ms = 0.0;
  double masks_ms = 0.0;
};

struct HullResult {
  Box3d box;  ///< from the LP, or the one given
  VisualHull hull;
  TriangleMesh mesh;
  MeshCheck mesh_check;
  HullTimings time;
};

/// The masks' bounds (run-length encoding the masks given as images, on `config.threads`
/// threads), the bounding box (the LP of eq. 8 unless `box` is given), each view's distance map
/// at the reduction distanceReduction() chooses for the box (in parallel), octree carving and
/// marching cubes. Throws HullBoxError when no box exists, std::invalid_argument for bad input.
/// `on_stage`, when given, is told each stage as it starts ("distance maps", "octree",
/// "mesh"), for a progress display.
HullResult buildHull(const HullInput& input, const HullConfig& config,
                     const std::optional<Box3d>& box = std::nullopt,
                     const std::function<void(const std::string& stage)>& on_stage = {});

/// The LP box of prepared views (hullBoundingBox of their cameras and bounds).
Box3d boundingBoxOf(const std::vector<HullView>& views);

}  // namespace sift_hull
