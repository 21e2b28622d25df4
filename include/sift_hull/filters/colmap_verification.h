#pragma once
// COLMAP's two-view geometric verification, run by its own command-line program on the same
// putative matches: a peer to measure the package's filters against (`--filter colmap`,
// `evaluate-filters`), not a part of the pipeline.

#include <string>

#include "sift_hull/features/matching.h"
#include "sift_hull/filters/filter_result.h"

namespace sift_hull {

/// The filter "colmap": the putative matches imported raw into a fresh COLMAP database
/// (`colmap feature_importer`, then `colmap matches_importer --match_type raw`), which verifies
/// them with COLMAP's defaults: SIMPLE_RADIAL cameras with a focal length prior of 1.2 times the
/// larger image side, its choice among F, E and H, an inlier threshold of 4 px
/// (SiftMatching.max_error), confidence 0.999, at least 15 inliers. The inliers it stores
/// (two_view_geometries) are kept. Keypoints are written in COLMAP's convention (the top left
/// pixel's centre at 0.5, 0.5); descriptors are not needed for raw matches and are written as
/// zeros. Score: 0 for a kept match, 1 otherwise.
struct ColmapConfig {
  std::string program = "colmap";  ///< the executable, looked up on PATH
  int seed = 0;                    ///< COLMAP's --random_seed
  int threads = 1;                 ///< SiftMatching.num_threads
};

/// Whether `program` can be run (found on PATH and `program help` exits 0); `why_not`, when
/// given, says what is missing ("colmap: not found on PATH; install the Debian package colmap").
bool colmapAvailable(const std::string& program = "colmap", std::string* why_not = nullptr);

/// Throws std::runtime_error when COLMAP is missing or fails (with the end of its log).
FilterResult filterColmap(const PutativeMatches& input, const ColmapConfig& config);

}  // namespace sift_hull
