#include "sift_hull/io/images.h"

#include <dirent.h>

#include <algorithm>
#include <cctype>
#include <exception>
#include <fstream>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "sift_hull/hull/view_silhouettes.h"
#include "sift_hull/io/reduced_images.h"

namespace sift_hull {
namespace {

/// cv::imread of a file, or an empty Mat when it is missing or undecodable. Existence is checked
/// first because cv::imread logs its own warning for a missing file.
cv::Mat readImageFile(const std::string& path, int flags) {
  return std::ifstream(path).good() ? cv::imread(path, flags) : cv::Mat();
}

}  // namespace

void checkImageSize(const CalibratedView& view, cv::Size image_size,
                    const std::string& image_path) {
  if (view.width_px == 0 && view.height_px == 0) return;
  // Compared in 64 bits: the calibration's sides are not limited to int.
  if (view.width_px == static_cast<uint64_t>(image_size.width) &&
      view.height_px == static_cast<uint64_t>(image_size.height)) {
    return;
  }
  throw std::runtime_error(view.size_source + ": the camera of view '" + view.name + "' is " +
                           std::to_string(view.width_px) + "x" + std::to_string(view.height_px) +
                           " (WIDTH x HEIGHT) but the image " + image_path + " is " +
                           std::to_string(image_size.width) + "x" +
                           std::to_string(image_size.height));
}

cv::Mat readImage(const std::string& path, int imread_flags) {
  cv::Mat image = readImageFile(path, imread_flags);
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
  checkImageSize(view, image.size(), path);
  return image;
}

namespace {

/// True for the file types whose images may carry an alpha channel.
bool mayHaveAlpha(const std::string& path) {
  const std::string::size_type dot = path.find_last_of('.');
  if (dot == std::string::npos) return false;
  std::string extension = path.substr(dot + 1);
  for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return extension == "png" || extension == "tif" || extension == "tiff" || extension == "webp";
}

/// An image as cv::IMREAD_COLOR gives it (BGR, 8 bits) from an IMREAD_UNCHANGED decoding.
cv::Mat asBgr8(const cv::Mat& raw) {
  cv::Mat eight = raw;
  if (raw.depth() == CV_16U) {
    raw.convertTo(eight, CV_8U, 1.0 / 257.0);
  } else if (raw.depth() != CV_8U) {
    raw.convertTo(eight, CV_8U, 255.0);
  }
  cv::Mat bgr;
  if (eight.channels() == 1) {
    cv::cvtColor(eight, bgr, cv::COLOR_GRAY2BGR);
  } else if (eight.channels() == 4) {
    cv::cvtColor(eight, bgr, cv::COLOR_BGRA2BGR);
  } else {
    bgr = eight;
  }
  return bgr;
}

}  // namespace

ViewImage loadViewImageWithAlpha(const std::string& directory, const CalibratedView& view) {
  const std::string path = directory + "/" + view.name;
  if (view.name.empty() || !mayHaveAlpha(path)) return {loadViewImage(directory, view), cv::Mat()};
  const cv::Mat raw = readImageFile(path, cv::IMREAD_UNCHANGED);
  if (raw.empty() || (raw.channels() != 1 && raw.channels() != 3 && raw.channels() != 4)) {
    return {loadViewImage(directory, view), cv::Mat()};  // its errors, or OpenCV's own conversion
  }
  checkImageSize(view, raw.size(), path);
  ViewImage image{asBgr8(raw), cv::Mat()};
  if (raw.channels() == 4) {
    cv::Mat alpha;
    cv::extractChannel(raw, alpha, 3);
    double low = 0.0, high = 0.0;
    cv::minMaxLoc(alpha, &low, &high);
    // A constant alpha says nothing about the object; half of full scale separates the two.
    const double full = raw.depth() == CV_16U ? 65535.0 : raw.depth() == CV_8U ? 255.0 : 1.0;
    if (low < high) cv::compare(alpha, 0.5 * full, image.alpha_mask, cv::CMP_GE);
  }
  return image;
}

ViewImage loadReducedViewImage(const std::string& directory, const CalibratedView& view,
                               int reduction, cv::Size* full_size) {
  const std::string path = directory + "/" + view.name;
  if (reduction > 1 && !view.name.empty() && hasJpegExtension(path) && std::ifstream(path).good()) {
    *full_size = imageFileSize(path);
    checkImageSize(view, *full_size, path);
    cv::Mat bgr = readImageReduced(path, reduction);
    if (bgr.size() == reducedSize(*full_size, reduction)) return {bgr, cv::Mat()};
    // Named .jpg but not decoded at scale (not a JPEG): decoded whole below.
  }
  ViewImage image = loadViewImageWithAlpha(directory, view);
  *full_size = image.bgr.size();
  if (reduction > 1) {
    image.bgr = reduceImage(image.bgr, reduction);
    if (!image.alpha_mask.empty()) image.alpha_mask = reduceMask(image.alpha_mask, reduction);
  }
  return image;
}

std::string maskPath(const std::string& mask_directory, const std::string& image_name) {
  const std::string same = mask_directory + "/" + image_name;
  if (std::ifstream(same).good()) return same;
  // The same number under another width or extension: image/000012.png against mask/012.png.
  const std::string::size_type slash = image_name.find_last_of('/');
  std::string stem = image_name.substr(slash == std::string::npos ? 0 : slash + 1);
  stem = stem.substr(0, stem.find_last_of('.'));
  if (stem.empty() || stem.size() > 18 ||
      stem.find_first_not_of("0123456789") != std::string::npos) {
    return same;
  }
  const unsigned long long number = std::stoull(stem);
  std::vector<std::string> candidates;
  if (DIR* dir = opendir(mask_directory.c_str())) {
    while (const dirent* entry = readdir(dir)) {
      std::string name = entry->d_name;
      const std::string::size_type dot = name.find_last_of('.');
      const std::string digits = name.substr(0, dot);
      if (digits.empty() || digits.size() > 18 ||
          digits.find_first_not_of("0123456789") != std::string::npos) {
        continue;
      }
      if (std::stoull(digits) == number) candidates.push_back(name);
    }
    closedir(dir);
  }
  if (candidates.size() != 1) return same;  // none, or ambiguous: the error names the plain path
  return mask_directory + "/" + candidates.front();
}

cv::Mat loadMask(const std::string& path) {
  const cv::Mat raw = readImageFile(path, cv::IMREAD_GRAYSCALE);
  if (raw.empty()) throw std::runtime_error(path + ": mask missing or unreadable");
  return maskInside(raw);
}

}  // namespace sift_hull
