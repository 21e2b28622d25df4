// Synthetic putative matches shared by the filter tests (test_local_filters, test_vote_ransac):
// a similarity pair, the right image turned and zoomed, two objects moving differently.
#pragma once

#include <cmath>
#include <opencv2/core.hpp>

#include "sift_hull/features/labelled_matches.h"
#include "sift_hull/filters/filter_result.h"
#include "sift_hull/synthetic/synthetic_matches.h"

namespace sift_hull {
namespace test {

/// 600 inliers of a similarity (rotation, scale about the image centre, 15 px shift, 0.5 px
/// noise), then random mismatches making `outliers` of all.
inline LabelledMatches synthetic(double outliers, unsigned seed, double rotation_deg = 20.0,
                                 double scale = 1.2) {
  SyntheticMatchConfig config;
  config.inliers = 600;
  config.outlier_fraction = outliers;
  config.seed = seed;
  config.rotation_deg = rotation_deg;
  config.scale = scale;
  return syntheticMatches(config);
}

/// The right image's putatives turned by `deg` and scaled by `scale` about the origin: points,
/// keypoint angles and sizes.
inline PutativeMatches transformRight(PutativeMatches input, double deg, double scale) {
  const double c = std::cos(deg * CV_PI / 180.0), s = std::sin(deg * CV_PI / 180.0);
  for (cv::KeyPoint& k : input.right_keypoints) {
    k.pt = cv::Point2f(static_cast<float>(scale * (c * k.pt.x - s * k.pt.y)),
                       static_cast<float>(scale * (s * k.pt.x + c * k.pt.y)));
    k.angle = static_cast<float>(std::fmod(k.angle + deg + 360.0, 360.0));
    k.size = static_cast<float>(k.size * scale);
  }
  return input;
}

inline size_t differing(const FilterResult& a, const FilterResult& b) {
  size_t count = 0;
  for (size_t m = 0; m < a.keep.size(); ++m) count += a.keep[m] != b.keep[m];
  return count;
}

/// Two objects side by side (images 1400 x 480), each following its own similarity (20 deg and
/// 1.2x; -35 deg and 0.8x), then 30 % random mismatches.
inline LabelledMatches twoMotions() {
  LabelledMatches a = synthetic(0.0, 13, 20.0, 1.2), b = synthetic(0.0, 17, -35.0, 0.8);
  const int offset = static_cast<int>(a.putative.left_keypoints.size());
  for (size_t m = 0; m < b.putative.matches.size(); ++m) {
    a.putative.left_keypoints.push_back(b.putative.left(m));
    a.putative.right_keypoints.push_back(b.putative.right(m));
    a.putative.left_keypoints.back().pt.x += 700.f;  // beside the first object
    a.putative.right_keypoints.back().pt.x += 700.f;
    a.putative.matches.emplace_back(offset + int(m), offset + int(m), 0.f);
    a.truth.push_back(b.truth[m]);
  }
  a.putative.left_image_size = a.putative.right_image_size = cv::Size(1400, 480);
  injectMismatches(&a, 0.3, 19);
  return a;
}

}  // namespace test
}  // namespace sift_hull
