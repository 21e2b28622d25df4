#include "sift_hull/hull/silhouette.h"

#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>

#include "sift_hull/limits.h"

namespace sift_hull {

void validate(const SilhouetteConfig& config) {
  if (!(config.threshold >= 0.0 && config.threshold <= 1.0)) {
    throw std::invalid_argument("SilhouetteConfig::threshold must be in [0, 1], got " +
                                std::to_string(config.threshold));
  }
  limits::requireInRange("SilhouetteConfig::dilate_px", config.dilate_px, 0,
                         limits::kMaxMorphologyRadiusPx);
  limits::requireInRange("SilhouetteConfig::erode_px", config.erode_px, 0,
                         limits::kMaxMorphologyRadiusPx);
}

cv::Mat silhouetteFromImage(const cv::Mat& image, const SilhouetteConfig& config) {
  validate(config);
  if (image.empty() || image.depth() != CV_8U) {
    throw std::invalid_argument("silhouetteFromImage needs a non-empty 8-bit image");
  }
  cv::Mat grey = image;
  if (image.channels() == 3) cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  cv::Mat mask;
  cv::threshold(grey, mask, config.threshold * 255.0, 255, cv::THRESH_BINARY);
  const auto disc = [](int radius) {
    return cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * radius + 1, 2 * radius + 1));
  };
  if (config.dilate_px > 0) cv::dilate(mask, mask, disc(config.dilate_px));
  if (config.erode_px > 0) cv::erode(mask, mask, disc(config.erode_px));
  return mask;
}

}  // namespace sift_hull
