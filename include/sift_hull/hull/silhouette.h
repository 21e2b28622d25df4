#pragma once

#include <opencv2/core.hpp>

namespace sift_hull {

/// Silhouette extraction by the Middlebury recipe: grey intensity above `threshold` (on [0, 1]),
/// then a dilation and an erosion with discs of the given radii.
struct SilhouetteConfig {
  double threshold = 0.19;
  int dilate_px = 10;
  int erode_px = 7;
};

/// Throws std::invalid_argument for a threshold outside [0, 1] or a radius outside
/// [0, limits::kMaxMorphologyRadiusPx].
void validate(const SilhouetteConfig& config);

/// Mask (CV_8UC1, 255 inside, 0 outside) of the object in an 8-bit grey or BGR image.
cv::Mat silhouetteFromImage(const cv::Mat& image, const SilhouetteConfig& config);

}  // namespace sift_hull
