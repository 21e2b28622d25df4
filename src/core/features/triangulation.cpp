#include "sift_hull/features/triangulation.h"

#include <optional>
#include <stdexcept>

namespace sift_hull {

std::vector<Eigen::Vector3d> triangulateMatches(const PinholeCamera& left,
                                                const PinholeCamera& right,
                                                const PutativeMatches& matches,
                                                const std::vector<uint8_t>& keep) {
  if (keep.size() != matches.matches.size()) {
    throw std::invalid_argument("triangulateMatches: " + std::to_string(keep.size()) +
                                " flags for " + std::to_string(matches.matches.size()) +
                                " matches");
  }
  std::vector<Eigen::Vector3d> points_W;
  for (size_t m = 0; m < matches.matches.size(); ++m) {
    if (!keep[m]) continue;
    const cv::Point2f& x_left = matches.left(m).pt;
    const cv::Point2f& x_right = matches.right(m).pt;
    const std::optional<Eigen::Vector3d> point = triangulate(
        left, right, Eigen::Vector2d(x_left.x, x_left.y), Eigen::Vector2d(x_right.x, x_right.y));
    if (point) points_W.push_back(*point);
  }
  return points_W;
}

}  // namespace sift_hull
