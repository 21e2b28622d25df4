#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "sift_hull/features/matching.h"
#include "sift_hull/geometry/camera.h"

namespace sift_hull {

/// The world points of the matches whose `keep` flag is set (one flag per match, e.g. a filter's
/// FilterResult::keep), by linear triangulation (triangulate()) from the left and the right
/// camera; matches that triangulate to no point (parallel rays, not in front) are left out.
/// Throws std::invalid_argument when `keep` has not one flag per match.
std::vector<Eigen::Vector3d> triangulateMatches(const PinholeCamera& left,
                                                const PinholeCamera& right,
                                                const PutativeMatches& matches,
                                                const std::vector<uint8_t>& keep);

}  // namespace sift_hull
