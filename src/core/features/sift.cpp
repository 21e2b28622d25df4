#include "sift_hull/features/sift.h"

#include <cmath>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>

namespace sift_hull {
namespace {

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

template <>
const SettingTable<SiftConfig>& settingsOf<SiftConfig>() {
  static const SettingTable<SiftConfig> table = [] {
    SettingTable<SiftConfig> t;
    t.add("max_features", &SiftConfig::max_features, "",
          "SIFT keypoints kept, the strongest; 0 keeps all")
        .atLeast(0);
    t.add("octave_layers", &SiftConfig::octave_layers, "", "SIFT scales per octave")
        .range(1, limits::kMaxOctaveLayers);
    t.add("contrast_threshold", &SiftConfig::contrast_threshold, "",
          "SIFT threshold on the DoG response (image values in [0, 1]), divided by octave_layers")
        .atLeast(0.0);
    t.add("edge_threshold", &SiftConfig::edge_threshold, "",
          "SIFT: largest principal-curvature ratio kept")
        .above(0.0);
    t.add("sigma_px", &SiftConfig::sigma_px, "px", "SIFT: blur of the first octave's base image")
        .above(0.0);
    t.add("max_image_pixels", &SiftConfig::max_image_pixels, "pixels",
          "larger images are refused (SIFT needs about 75 bytes per pixel of a pair)")
        .atLeast(1);
    return t;
  }();
  return table;
}

void validate(const SiftConfig& config) { checkSettings(config, "SiftConfig"); }

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
