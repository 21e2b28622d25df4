#pragma once

#include <Eigen/Core>
#include <cmath>
#include <limits>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "sift_hull/features/sift.h"
#include "sift_hull/geometry/camera.h"
#include "sift_hull/settings.h"

namespace sift_hull {

/// Euclidean nearest-neighbour matching of descriptors from the left image to the right one.
struct MatchConfig {
  /// Largest descriptor distance kept (SIFT descriptors have norm 512); raising it gives denser,
  /// dirtier matches. 0 keeps every nearest neighbour.
  double max_descriptor_distance = 0.0;
  /// Lowe's ratio test: keep when nearest < ratio * second nearest. 1 (or more) turns it off.
  double ratio = 0.8;
  bool cross_check = false;  ///< keep only mutual nearest neighbours
  /// "blas" (exact, by matrix product: exactNearestNeighbours), "brute-force" (exact, OpenCV's
  /// BFMatcher) or "flann" (approximate, kd-trees).
  std::string backend = "blas";
};
/// Its settings: names, units, ranges, help (sift_hull/settings.h).
template <>
const SettingTable<MatchConfig>& settingsOf<MatchConfig>();

/// Throws std::invalid_argument naming the first bad field.
void validate(const MatchConfig& config);

/// Putative matches between two images: what every match filter takes.
struct PutativeMatches {
  std::vector<cv::KeyPoint> left_keypoints;
  std::vector<cv::KeyPoint> right_keypoints;
  std::vector<cv::DMatch> matches;  ///< queryIdx indexes left_keypoints, trainIdx right_keypoints
  cv::Size left_image_size;
  cv::Size right_image_size;
  /// Fundamental matrix with x_r^T F x_l = 0, when the pair is calibrated: between ideal pixels
  /// (undistorted, see PinholeCamera) when `cameras` holds a lens distortion.
  std::optional<Eigen::Matrix3d> F_right_left;
  /// The pair's cameras (left, right) when calibrated by calibratePair: the epipolar filter
  /// undistorts the points with their lens distortion before F.
  std::optional<std::pair<PinholeCamera, PinholeCamera>> cameras;

  const cv::KeyPoint& left(size_t match) const { return left_keypoints[matches[match].queryIdx]; }
  const cv::KeyPoint& right(size_t match) const { return right_keypoints[matches[match].trainIdx]; }
  /// False when either point of the match has a NaN or infinite coordinate.
  bool hasFinitePositions(size_t match) const {
    const cv::Point2f &a = left(match).pt, &b = right(match).pt;
    return std::isfinite(a.x) && std::isfinite(a.y) && std::isfinite(b.x) && std::isfinite(b.y);
  }
};

/// Nearest neighbours of each left descriptor among the right ones, filtered as `config` says.
std::vector<cv::DMatch> matchDescriptors(const cv::Mat& left, const cv::Mat& right,
                                         const MatchConfig& config);

/// Guided matching of a calibrated pair: each left keypoint's two nearest descriptors among the
/// right keypoints within max_epipolar_px of its epipolar line (ideal pixels, both ways), then
/// config's distance and ratio tests among those (cross_check and backend do not apply). Wide
/// baselines keep the matches that the ratio test against every right keypoint loses. Throws
/// std::invalid_argument for descriptors that do not fit their keypoints.
std::vector<cv::DMatch> matchAlongEpipolarLines(const Features& left, const Features& right,
                                                const PinholeCamera& left_camera,
                                                const PinholeCamera& right_camera,
                                                const MatchConfig& config, double max_epipolar_px);

/// Matches described images: the putative matches of the two feature sets (copied in).
PutativeMatches matchFeatures(const Features& left, const Features& right, cv::Size left_size,
                              cv::Size right_size, const MatchConfig& matching);

/// Detects and describes both images (the right one on a second thread) and matches them.
PutativeMatches matchImages(const cv::Mat& left_image, const cv::Mat& right_image,
                            const SiftConfig& sift, const MatchConfig& matching);

/// Calibrates a pair: `cameras` and F_right_left = fundamentalMatrix(left, right).
void calibratePair(PutativeMatches* matches, const PinholeCamera& left, const PinholeCamera& right);

/// Fundamental matrix of a rectified pair: epipolar lines are image rows (y_r = y_l).
Eigen::Matrix3d rectifiedFundamentalMatrix();

}  // namespace sift_hull
