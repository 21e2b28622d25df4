#include "sift_hull/features/sift.h"

#include <cmath>
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
  require(config.octave_layers >= 1 && config.octave_layers <= limits::kMaxOctaveLayers,
          "octave_layers must be in [1, " + std::to_string(limits::kMaxOctaveLayers) + "]");
  require(config.contrast_threshold >= 0.0 && std::isfinite(config.contrast_threshold),
          "contrast_threshold must be finite and >= 0");
  require(config.edge_threshold > 0.0 && std::isfinite(config.edge_threshold),
          "edge_threshold must be finite and > 0");
  require(config.sigma_px > 0.0 && std::isfinite(config.sigma_px),
          "sigma_px must be finite and > 0");
  require(config.max_image_pixels >= 1, "max_image_pixels must be >= 1");
}

void checkImageSize(const cv::Mat& image, const SiftConfig& config) {
  const size_t pixels = static_cast<size_t>(image.cols) * static_cast<size_t>(image.rows);
  if (pixels > config.max_image_pixels) {
    throw std::invalid_argument("the image is " + std::to_string(image.cols) + "x" +
                                std::to_string(image.rows) + " = " + std::to_string(pixels) +
                                " pixels, more than max_image_pixels (" +
                                std::to_string(config.max_image_pixels) + ")");
  }
}

Features detectSift(const cv::Mat& image, const SiftConfig& config) {
  validate(config);
  checkImageSize(image, config);
  const cv::Ptr<cv::SIFT> sift =
      cv::SIFT::create(config.max_features, config.octave_layers, config.contrast_threshold,
                       config.edge_threshold, config.sigma_px);
  Features features;
  sift->detectAndCompute(greyImage(image), cv::noArray(), features.keypoints, features.descriptors);
  return features;
}

}  // namespace sift_hull
