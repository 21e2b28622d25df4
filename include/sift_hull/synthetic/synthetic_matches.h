#pragma once

#include <opencv2/core.hpp>
#include <vector>

#include "sift_hull/features/labelled_matches.h"
#include "sift_hull/features/matching.h"

namespace sift_hull {

/// Putative matches with known truth: inliers whose right keypoints are a similarity transform of
/// the left ones (position, orientation and scale, plus noise), then random outliers.
struct SyntheticMatchConfig {
  size_t inliers = 1000;
  double outlier_fraction = 0.3;  ///< share of outliers among all matches, in [0, 1)
  cv::Size image_size{640, 480};
  double rotation_deg = 20.0;  ///< right = rotation and scale about the image centre, then shift
  double scale = 1.2;
  double shift_px = 15.0;
  double position_noise_px = 0.5;
  double angle_noise_deg = 3.0;
  unsigned seed = 1;
};

/// Inliers first, then outliers; inlier right points that leave the image are drawn again.
LabelledMatches syntheticMatches(const SyntheticMatchConfig& config);

/// Appends random mismatches so that they make `fraction` (in [0, 1)) of all matches: keypoints
/// at uniform random positions in each image, with random orientations and the scales of existing
/// keypoints. Their truth is kWrong.
void injectMismatches(LabelledMatches* matches, double fraction, unsigned seed);

/// Copies of the matches tiled `copies_x` by `copies_y` times, each copy shifted by a multiple of
/// the image size in both images alike (a rectified pair stays rectified): a larger input with
/// the same local structure, for timing.
LabelledMatches tileMatches(const LabelledMatches& matches, int copies_x, int copies_y);

}  // namespace sift_hull
