#include "sift_hull/features.h"

#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>

namespace sift_hull {
namespace {

void require(bool condition, const std::string& message) {
  if (!condition) throw std::invalid_argument("SiftConfig: " + message);
}

cv::Mat greyImage(const cv::Mat& image) {
  if (image.empty()) throw std::invalid_argument("detectSift: empty image");
  if (image.depth() != CV_8U) throw std::invalid_argument("detectSift: image must be 8-bit");
  if (image.channels() == 1) return image;
  cv::Mat grey;
  if (image.channels() == 3) {
    cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  } else if (image.channels() == 4) {
    cv::cvtColor(image, grey, cv::COLOR_BGRA2GRAY);
  } else {
    throw std::invalid_argument("detectSift: image must have 1, 3 or 4 channels");
  }
  return grey;
}

}  // namespace

void validate(const SiftConfig& config) {
  require(config.max_features >= 0, "max_features must be >= 0");
  require(config.octave_layers >= 1, "octave_layers must be >= 1");
  require(config.contrast_threshold >= 0.0, "contrast_threshold must be >= 0");
  require(config.edge_threshold > 0.0, "edge_threshold must be > 0");
  require(config.sigma_px > 0.0, "sigma_px must be > 0");
}

Features detectSift(const cv::Mat& image, const SiftConfig& config) {
  validate(config);
  const cv::Ptr<cv::SIFT> sift =
      cv::SIFT::create(config.max_features, config.octave_layers, config.contrast_threshold,
                       config.edge_threshold, config.sigma_px);
  Features features;
  sift->detectAndCompute(greyImage(image), cv::noArray(), features.keypoints, features.descriptors);
  return features;
}

}  // namespace sift_hull
