#include "sift_hull/features/matching.h"

#include <cmath>
#include <opencv2/features2d.hpp>
#include <stdexcept>

namespace sift_hull {
namespace {

void require(bool condition, const std::string& message) {
  if (!condition) throw std::invalid_argument("MatchConfig: " + message);
}

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

}  // namespace

void validate(const MatchConfig& config) {
  require(config.max_descriptor_distance > 0.0, "max_descriptor_distance must be > 0");
  require(config.ratio > 0.0, "ratio must be > 0 (1 turns the test off)");
  require(config.backend == "brute-force" || config.backend == "flann",
          "backend must be 'brute-force' or 'flann', not '" + config.backend + "'");
}

std::vector<cv::DMatch> matchDescriptors(const cv::Mat& left, const cv::Mat& right,
                                         const MatchConfig& config) {
  validate(config);
  if (left.empty() || right.empty()) return {};
  if (left.cols != right.cols || left.type() != CV_32F || right.type() != CV_32F) {
    throw std::invalid_argument("matchDescriptors: descriptors must be CV_32F of equal length");
  }
  std::vector<std::vector<cv::DMatch>> neighbours;
  makeMatcher(config.backend)->knnMatch(left, right, neighbours, 2);
  std::vector<int> reverse;
  if (config.cross_check) reverse = reverseNearest(left, right, config.backend);
  std::vector<cv::DMatch> matches;
  for (const std::vector<cv::DMatch>& candidates : neighbours) {
    if (candidates.empty()) continue;
    const cv::DMatch& best = candidates.front();
    if (best.distance > config.max_descriptor_distance) continue;
    if (!passesRatio(candidates, config.ratio)) continue;
    if (config.cross_check && reverse[best.trainIdx] != best.queryIdx) continue;
    matches.push_back(best);
  }
  return matches;
}

PutativeMatches matchImages(const cv::Mat& left_image, const cv::Mat& right_image,
                            const SiftConfig& sift, const MatchConfig& matching) {
  validate(matching);
  Features left = detectSift(left_image, sift);
  Features right = detectSift(right_image, sift);
  PutativeMatches result;
  result.matches = matchDescriptors(left.descriptors, right.descriptors, matching);
  result.left_keypoints = std::move(left.keypoints);
  result.right_keypoints = std::move(right.keypoints);
  result.left_image_size = left_image.size();
  result.right_image_size = right_image.size();
  return result;
}

bool PutativeMatches::hasFinitePositions(size_t match) const {
  const cv::Point2f& a = left(match).pt;
  const cv::Point2f& b = right(match).pt;
  return std::isfinite(a.x) && std::isfinite(a.y) && std::isfinite(b.x) && std::isfinite(b.y);
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
