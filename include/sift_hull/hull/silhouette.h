#pragma once

#include <opencv2/core.hpp>
#include <string>

namespace sift_hull {

/// Silhouette extraction from an image. Two methods:
/// - "threshold", the Middlebury recipe: grey intensity above `threshold` (on [0, 1]), then a
///   dilation and an erosion with discs of the given radii;
/// - "background", a colour model of the image border (the object rarely touches it): each
///   pixel's colour distance (CIE Lab) to the nearest of the border's colour clusters, a threshold
///   on that distance chosen per image (Otsu), the same dilation and erosion, and the holes of the
///   object filled. It needs no threshold from the user.
struct SilhouetteConfig {
  std::string silhouette_method = "threshold";  ///< "threshold" or "background"
  double threshold = 0.19;
  int dilate_px = 10;
  int erode_px = 7;
};

/// Throws std::invalid_argument for a threshold outside [0, 1] or a radius outside
/// [0, limits::kMaxMorphologyRadiusPx].
void validate(const SilhouetteConfig& config);

/// Mask (CV_8UC1, 255 inside, 0 outside) of the object in an 8-bit grey or BGR image, by the
/// config's method.
cv::Mat silhouetteFromImage(const cv::Mat& image, const SilhouetteConfig& config);

/// The colour distance of every pixel (CV_32FC1, CIE Lab units) to the nearest colour cluster of
/// the image's border band (`border_fraction` of the smaller side, at least 2 pixels wide): the
/// "background" method's evidence, before its threshold.
cv::Mat backgroundDistance(const cv::Mat& image, double border_fraction = 0.03);

}  // namespace sift_hull
