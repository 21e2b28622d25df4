#pragma once

#include <opencv2/core.hpp>
#include <vector>

#include "sift_hull/limits.h"
#include "sift_hull/settings.h"

namespace sift_hull {

/// Parameters of OpenCV's SIFT detector (cv::SIFT::create), with OpenCV's defaults.
struct SiftConfig {
  int max_features = 0;              ///< keep the strongest this many; 0 keeps all
  int octave_layers = 3;             ///< scales per octave
  double contrast_threshold = 0.04;  ///< on DoG response (image values in [0, 1]), / octave_layers
  double edge_threshold = 10.0;      ///< largest principal-curvature ratio kept
  double sigma_px = 1.6;             ///< blur of the first octave's base image
  /// Larger images are refused (detectSift throws): SIFT needs about 75 bytes per pixel of a
  /// pair, so 25 megapixels (a 6000x4000 photo) keep a pair within 4 GiB.
  size_t max_image_pixels = limits::kDefaultMaxImagePixels;
};
/// Its settings: names, units, ranges, help (sift_hull/settings.h).
template <>
const SettingTable<SiftConfig>& settingsOf<SiftConfig>();

/// Throws std::invalid_argument naming the first bad field.
void validate(const SiftConfig& config);

/// SIFT keypoints and their descriptors. KeyPoint::angle is the main orientation in degrees,
/// measured in image coordinates (x right, y down), so it turns with the image content.
struct Features {
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;  ///< CV_32FC1, one 128-D row per keypoint
};

/// Throws std::invalid_argument when the image has more than config.max_image_pixels pixels.
void checkImageSize(const cv::Mat& image, const SiftConfig& config);

/// Detects and describes SIFT features in a colour (BGR) or grey 8-bit image. Throws
/// std::invalid_argument for a bad config, an empty image or one over max_image_pixels.
Features detectSift(const cv::Mat& image, const SiftConfig& config = SiftConfig());

}  // namespace sift_hull
