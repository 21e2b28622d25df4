#pragma once

#include <optional>
#include <string>
#include <vector>

#include "sift_hull/dataset.h"
#include "sift_hull/mesh.h"
#include "sift_hull/scene.h"
#include "sift_hull/visual_hull.h"

namespace sift_hull {

/// Calibrated silhouettes, one entry per view in each vector.
struct HullInput {
  std::vector<std::string> names;
  std::vector<PinholeCamera> cameras;
  std::vector<cv::Mat> masks;  ///< CV_8UC1, non-zero inside
};

/// The views of a calibration file named in `view_names` (all when empty), in the file's order,
/// with silhouettes as loadSilhouettes() finds them. Throws std::runtime_error for a name that the
/// calibration does not hold.
HullInput loadHullInput(const std::string& calibration_path, const std::string& image_directory,
                        const std::string& mask_directory, const SilhouetteConfig& recipe,
                        const std::vector<std::string>& view_names);

/// The names, cameras and masks of rendered views.
HullInput hullInputOf(const std::vector<RenderedView>& views);

/// Image names listed in a file, one per line; blank lines and '#' comments skipped.
std::vector<std::string> readViewList(const std::string& path);

/// Wall-clock times of the stages of buildHull, in milliseconds.
struct HullTimings {
  double distance_ms = 0.0, bbox_ms = 0.0, octree_ms = 0.0, mesh_ms = 0.0, total_ms = 0.0;
};

struct HullResult {
  Box3d box;  ///< from the LP, or the one given
  VisualHull hull;
  TriangleMesh mesh;
  MeshCheck mesh_check;
  HullTimings time;
};

/// Distance transforms, bounding box (the LP of eq. 8 unless `box` is given), octree carving and
/// marching cubes. Throws HullBoxError when no box exists, std::invalid_argument for bad input.
HullResult buildHull(const HullInput& input, const HullConfig& config,
                     const std::optional<Box3d>& box = std::nullopt);

/// The LP box of prepared views (hullBoundingBox of their cameras and bounds).
Box3d boundingBoxOf(const std::vector<HullView>& views);

}  // namespace sift_hull
