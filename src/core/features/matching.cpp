#include "sift_hull/features/matching.h"

#include <cmath>
#include <future>
#include <limits>
#include <opencv2/features2d.hpp>
#include <optional>
#include <stdexcept>

#include "sift_hull/features/nearest_neighbours.h"
#include "sift_hull/settings.h"

namespace sift_hull {
namespace {

cv::Ptr<cv::DescriptorMatcher> makeMatcher(const std::string& backend) {
  if (backend == "flann") return cv::FlannBasedMatcher::create();
  return cv::BFMatcher::create(cv::NORM_L2);
}

/// Lowe's test on the two nearest neighbours; a lone neighbour has no rival and passes.
bool passesRatio(const std::vector<cv::DMatch>& neighbours, double ratio) {
  if (neighbours.size() < 2 || ratio >= 1.0) return true;
  return neighbours[0].distance < ratio * neighbours[1].distance;
}

/// For each right descriptor, its nearest left descriptor's index.
std::vector<int> reverseNearest(const cv::Mat& left, const cv::Mat& right,
                                const std::string& backend) {
  std::vector<cv::DMatch> reverse;
  makeMatcher(backend)->match(right, left, reverse);
  std::vector<int> nearest(right.rows, -1);
  for (const cv::DMatch& match : reverse) nearest[match.queryIdx] = match.trainIdx;
  return nearest;
}

/// The largest descriptor distance kept: max_descriptor_distance, or infinity for 0 (no limit).
double descriptorLimit(const MatchConfig& config) {
  return config.max_descriptor_distance > 0.0 ? config.max_descriptor_distance
                                              : std::numeric_limits<double>::infinity();
}

}  // namespace

template <>
const SettingTable<MatchConfig>& settingsOf<MatchConfig>() {
  static const SettingTable<MatchConfig> table = [] {
    SettingTable<MatchConfig> t;
    t.add("ratio", &MatchConfig::ratio, "",
          "Lowe's ratio test: a match is kept when its descriptor distance is below this times "
          "the second nearest's; 1 turns the test off")
        .above(0.0, 1.0)
        .tunedAtRunTime();
    t.add("max_descriptor_distance", &MatchConfig::max_descriptor_distance, "",
          "largest SIFT descriptor distance kept (descriptors have norm 512); 0: no limit")
        .range(0.0, 1024.0)
        .tunedAtRunTime();
    t.add("cross_check", &MatchConfig::cross_check, "", "keep only mutual nearest neighbours")
        .tunedAtRunTime();
    t.add("backend", &MatchConfig::backend, "",
          "nearest neighbours: blas (exact, by matrix product), brute-force (exact, OpenCV's "
          "BFMatcher) or flann (approximate, kd-trees)")
        .oneOf({"blas", "brute-force", "flann"});
    return t;
  }();
  return table;
}

void validate(const MatchConfig& config) { checkSettings(config, "MatchConfig"); }

namespace {

/// Ideal pixels of keypoints (NaN where the distortion cannot be undone).
std::vector<Eigen::Vector3d> idealPoints(const std::vector<cv::KeyPoint>& keypoints,
                                         const PinholeCamera& camera) {
  std::vector<Eigen::Vector3d> points;
  points.reserve(keypoints.size());
  for (const cv::KeyPoint& k : keypoints) {
    const std::optional<Eigen::Vector2d> ideal = camera.undistortPixel({k.pt.x, k.pt.y});
    points.push_back(ideal ? Eigen::Vector3d(ideal->x(), ideal->y(), 1.0)
                           : Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN()));
  }
  return points;
}

/// A line (a, b, c) scaled so that a x + b y + c is the distance in pixels.
Eigen::Vector3d unitLine(const Eigen::Vector3d& line) {
  return line / std::hypot(line.x(), line.y());
}

}  // namespace

std::vector<cv::DMatch> matchAlongEpipolarLines(const Features& left, const Features& right,
                                                const PinholeCamera& left_camera,
                                                const PinholeCamera& right_camera,
                                                const MatchConfig& config, double max_epipolar_px) {
  validate(config);
  if (!(max_epipolar_px > 0.0)) {
    throw std::invalid_argument("matchAlongEpipolarLines: max_epipolar_px must be > 0");
  }
  if (left.descriptors.rows != static_cast<int>(left.keypoints.size()) ||
      right.descriptors.rows != static_cast<int>(right.keypoints.size()) ||
      (!left.keypoints.empty() && !right.keypoints.empty() &&
       (left.descriptors.cols != right.descriptors.cols || left.descriptors.type() != CV_32F ||
        right.descriptors.type() != CV_32F))) {
    throw std::invalid_argument("matchAlongEpipolarLines: descriptors do not fit the keypoints");
  }
  const Eigen::Matrix3d F = fundamentalMatrix(left_camera, right_camera);
  const std::vector<Eigen::Vector3d> x_left = idealPoints(left.keypoints, left_camera);
  const std::vector<Eigen::Vector3d> x_right = idealPoints(right.keypoints, right_camera);
  std::vector<Eigen::Vector3d> lines_in_left(x_right.size());
  for (size_t j = 0; j < x_right.size(); ++j)
    lines_in_left[j] = unitLine(F.transpose() * x_right[j]);
  std::vector<cv::DMatch> matches;
  for (size_t i = 0; i < x_left.size(); ++i) {
    const Eigen::Vector3d line = unitLine(F * x_left[i]);
    if (!line.allFinite()) continue;
    float best = std::numeric_limits<float>::infinity(), second = best;
    int best_j = -1;
    for (size_t j = 0; j < x_right.size(); ++j) {
      if (!(std::abs(line.dot(x_right[j])) <= max_epipolar_px) ||
          !(std::abs(lines_in_left[j].dot(x_left[i])) <= max_epipolar_px)) {
        continue;
      }
      const float distance =
          static_cast<float>(cv::norm(left.descriptors.row(static_cast<int>(i)),
                                      right.descriptors.row(static_cast<int>(j)), cv::NORM_L2));
      if (distance < best) {
        second = best, best = distance, best_j = static_cast<int>(j);
      } else if (distance < second) {
        second = distance;
      }
    }
    if (best_j < 0 || best > descriptorLimit(config)) continue;
    if (config.ratio < 1.0 && std::isfinite(second) && !(best < config.ratio * second)) continue;
    matches.emplace_back(static_cast<int>(i), best_j, best);
  }
  return matches;
}

namespace {

/// The blas backend: both nearest neighbours and the mutual check from one pass.
std::vector<cv::DMatch> matchByMatrixProduct(const cv::Mat& left, const cv::Mat& right,
                                             const MatchConfig& config) {
  const NearestNeighbours nn = exactNearestNeighbours(left, right, config.cross_check);
  std::vector<cv::DMatch> matches;
  for (size_t i = 0; i < nn.forward.size(); ++i) {
    const TwoNearest& n = nn.forward[i];
    if (n.best < 0 || n.best_distance > descriptorLimit(config)) continue;
    if (config.ratio < 1.0 && n.second >= 0 &&
        !(n.best_distance < config.ratio * n.second_distance))
      continue;
    if (config.cross_check && nn.reverse_nearest[n.best] != static_cast<int>(i)) continue;
    matches.emplace_back(static_cast<int>(i), n.best, n.best_distance);
  }
  return matches;
}

}  // namespace

std::vector<cv::DMatch> matchDescriptors(const cv::Mat& left, const cv::Mat& right,
                                         const MatchConfig& config) {
  validate(config);
  if (left.empty() || right.empty()) return {};
  if (left.cols != right.cols || left.type() != CV_32F || right.type() != CV_32F) {
    throw std::invalid_argument("matchDescriptors: descriptors must be CV_32F of equal length");
  }
  if (config.backend == "blas") return matchByMatrixProduct(left, right, config);
  std::vector<std::vector<cv::DMatch>> neighbours;
  makeMatcher(config.backend)->knnMatch(left, right, neighbours, 2);
  std::vector<int> reverse;
  if (config.cross_check) reverse = reverseNearest(left, right, config.backend);
  std::vector<cv::DMatch> matches;
  for (const std::vector<cv::DMatch>& candidates : neighbours) {
    if (candidates.empty()) continue;
    const cv::DMatch& best = candidates.front();
    if (best.distance > descriptorLimit(config)) continue;
    if (!passesRatio(candidates, config.ratio)) continue;
    if (config.cross_check && reverse[best.trainIdx] != best.queryIdx) continue;
    matches.push_back(best);
  }
  return matches;
}

PutativeMatches matchFeatures(const Features& left, const Features& right, cv::Size left_size,
                              cv::Size right_size, const MatchConfig& matching) {
  PutativeMatches result;
  result.matches = matchDescriptors(left.descriptors, right.descriptors, matching);
  result.left_keypoints = left.keypoints;
  result.right_keypoints = right.keypoints;
  result.left_image_size = left_size;
  result.right_image_size = right_size;
  return result;
}

PutativeMatches matchImages(const cv::Mat& left_image, const cv::Mat& right_image,
                            const SiftConfig& sift, const MatchConfig& matching) {
  validate(matching);
  std::future<Features> right_features =
      std::async(std::launch::async, [&] { return detectSift(right_image, sift); });
  Features left;
  try {
    left = detectSift(left_image, sift);
  } catch (...) {
    right_features.wait();  // the other thread reads the caller's image: let it finish first
    throw;
  }
  Features right = right_features.get();
  PutativeMatches result;
  result.matches = matchDescriptors(left.descriptors, right.descriptors, matching);
  result.left_keypoints = std::move(left.keypoints);
  result.right_keypoints = std::move(right.keypoints);
  result.left_image_size = left_image.size();
  result.right_image_size = right_image.size();
  return result;
}

Eigen::Matrix3d rectifiedFundamentalMatrix() {
  Eigen::Matrix3d F;
  F << 0, 0, 0, 0, 0, -1, 0, 1, 0;
  return F;
}

void calibratePair(PutativeMatches* matches, const PinholeCamera& left,
                   const PinholeCamera& right) {
  matches->cameras = std::make_pair(left, right);
  matches->F_right_left = fundamentalMatrix(left, right);
}

}  // namespace sift_hull
