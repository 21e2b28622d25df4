#include "sift_hull/io/images.h"

#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <stdexcept>

namespace sift_hull {
namespace {

/// cv::imread of a file, or an empty Mat when it is missing or undecodable. Existence is checked
/// first because cv::imread logs its own warning for a missing file.
cv::Mat readImageFile(const std::string& path, int flags) {
  return std::ifstream(path).good() ? cv::imread(path, flags) : cv::Mat();
}

}  // namespace

cv::Mat readImage(const std::string& path) {
  cv::Mat image = readImageFile(path, cv::IMREAD_COLOR);
  if (image.empty()) throw std::runtime_error(path + ": image missing or unreadable");
  return image;
}

cv::Mat loadViewImage(const std::string& directory, const CalibratedView& view) {
  const std::string named_at = view.source.empty() ? "" : " (named at " + view.source + ")";
  if (view.name.empty()) {
    throw std::runtime_error((view.source.empty() ? "a view" : view.source) +
                             ": no image name for this view; put one before its numbers");
  }
  const std::string path = directory + "/" + view.name;
  cv::Mat image = readImageFile(path, cv::IMREAD_COLOR);
  if (image.empty()) throw std::runtime_error(path + ": image missing or unreadable" + named_at);
  return image;
}

cv::Mat loadMask(const std::string& path) {
  const cv::Mat raw = readImageFile(path, cv::IMREAD_GRAYSCALE);
  if (raw.empty()) throw std::runtime_error(path + ": mask missing or unreadable");
  cv::Mat mask;
  cv::compare(raw, 0, mask, cv::CMP_GT);
  return mask;
}

std::vector<cv::Mat> loadSilhouettes(const std::vector<CalibratedView>& views,
                                     const std::string& image_directory,
                                     const std::string& mask_directory,
                                     const SilhouetteConfig& recipe) {
  std::vector<cv::Mat> silhouettes;
  for (const CalibratedView& view : views) {
    const cv::Mat image = loadViewImage(image_directory, view);
    if (!silhouettes.empty() && image.size() != silhouettes.front().size()) {
      throw std::runtime_error(image_directory + "/" + view.name + ": image size differs from " +
                               views.front().name + "'s (" + std::to_string(image.cols) + "x" +
                               std::to_string(image.rows) + ", not " +
                               std::to_string(silhouettes.front().cols) + "x" +
                               std::to_string(silhouettes.front().rows) +
                               "): one calibration set is for one image size");
    }
    if (mask_directory.empty()) {
      silhouettes.push_back(silhouetteFromImage(image, recipe));
      continue;
    }
    const std::string path = mask_directory + "/" + view.name;
    silhouettes.push_back(loadMask(path));
    if (silhouettes.back().size() != image.size()) {
      throw std::runtime_error(path + ": mask size differs from the image's");
    }
  }
  return silhouettes;
}

}  // namespace sift_hull
