#include "sift_hull/hull/silhouette.h"

#include <algorithm>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "sift_hull/limits.h"

namespace sift_hull {

void validate(const SilhouetteConfig& config) {
  if (config.silhouette_method != "threshold" && config.silhouette_method != "background") {
    throw std::invalid_argument(
        "SilhouetteConfig::silhouette_method must be threshold or background, not '" +
        config.silhouette_method + "'");
  }
  if (!(config.threshold >= 0.0 && config.threshold <= 1.0)) {
    throw std::invalid_argument("SilhouetteConfig::threshold must be in [0, 1], got " +
                                std::to_string(config.threshold));
  }
  limits::requireInRange("SilhouetteConfig::dilate_px", config.dilate_px, 0,
                         limits::kMaxMorphologyRadiusPx);
  limits::requireInRange("SilhouetteConfig::erode_px", config.erode_px, 0,
                         limits::kMaxMorphologyRadiusPx);
}

namespace {

/// The least share of the border a background colour cluster holds.
constexpr double kMinClusterShare = 0.05;

cv::Mat disc(int radius) {
  return cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * radius + 1, 2 * radius + 1));
}

/// The image as CV_32FC3 CIE Lab (L in [0, 100]).
cv::Mat labOf(const cv::Mat& image) {
  cv::Mat bgr = image;
  if (image.channels() == 1) cv::cvtColor(image, bgr, cv::COLOR_GRAY2BGR);
  cv::Mat scaled, lab;
  bgr.convertTo(scaled, CV_32FC3, 1.0 / 255.0);
  cv::cvtColor(scaled, lab, cv::COLOR_BGR2Lab);
  return lab;
}

/// Up to `most` Lab colours of the band of `width` pixels along the image border, evenly spaced.
cv::Mat borderSamples(const cv::Mat& lab, int width, int most) {
  std::vector<cv::Vec3f> samples;
  for (int v = 0; v < lab.rows; ++v) {
    const bool band_row = v < width || v >= lab.rows - width;
    for (int u = 0; u < lab.cols; ++u) {
      if (band_row || u < width || u >= lab.cols - width)
        samples.push_back(lab.at<cv::Vec3f>(v, u));
    }
  }
  const size_t step = std::max<size_t>(1, samples.size() / static_cast<size_t>(most));
  cv::Mat out;
  for (size_t i = 0; i < samples.size(); i += step) out.push_back(cv::Mat(samples[i]).t());
  return out.reshape(1);
}

/// Fills the holes of a mask: what the outside cannot reach from the image border.
cv::Mat filledHoles(const cv::Mat& mask) {
  cv::Mat padded;
  cv::copyMakeBorder(mask, padded, 1, 1, 1, 1, cv::BORDER_CONSTANT, 0);
  cv::Mat reached = padded.clone();
  cv::floodFill(reached, cv::Point(0, 0), 255);
  cv::Mat holes;
  cv::bitwise_not(reached, holes);
  cv::Mat filled = padded | holes;
  return filled(cv::Rect(1, 1, mask.cols, mask.rows)).clone();
}

cv::Mat thresholdSilhouette(const cv::Mat& image, const SilhouetteConfig& config) {
  cv::Mat grey = image;
  if (image.channels() == 3) cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  cv::Mat mask;
  cv::threshold(grey, mask, config.threshold * 255.0, 255, cv::THRESH_BINARY);
  if (config.dilate_px > 0) cv::dilate(mask, mask, disc(config.dilate_px));
  if (config.erode_px > 0) cv::erode(mask, mask, disc(config.erode_px));
  return mask;
}

cv::Mat backgroundSilhouette(const cv::Mat& image, const SilhouetteConfig& config) {
  const cv::Mat distance = backgroundDistance(image);
  // Otsu on the distance, clipped at 100 Lab units (a colour that far is object whatever else).
  cv::Mat levels;
  distance.convertTo(levels, CV_8U, 255.0 / 100.0);
  cv::Mat mask;
  cv::threshold(levels, mask, 0, 255, cv::THRESH_BINARY | cv::THRESH_OTSU);
  // The recipe's dilation and erosion join what a dark fold of the object split; then the holes
  // are filled.
  if (config.dilate_px > 0) cv::dilate(mask, mask, disc(config.dilate_px));
  if (config.erode_px > 0) cv::erode(mask, mask, disc(config.erode_px));
  return filledHoles(mask);
}

}  // namespace

cv::Mat backgroundDistance(const cv::Mat& image, double border_fraction) {
  if (image.empty() || image.depth() != CV_8U || (image.channels() != 1 && image.channels() != 3)) {
    throw std::invalid_argument("backgroundDistance needs a non-empty 8-bit grey or BGR image");
  }
  const cv::Mat lab = labOf(image);
  const int width = std::max(2, static_cast<int>(border_fraction * std::min(lab.rows, lab.cols)));
  const cv::Mat samples =
      borderSamples(lab, std::min(width, std::min(lab.rows, lab.cols) / 2), 4000);
  const int clusters = std::min(8, samples.rows);
  cv::Mat labels, centres;
  cv::setRNGSeed(1);  // deterministic clusters
  cv::kmeans(samples, clusters, labels,
             cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 20, 0.5), 3,
             cv::KMEANS_PP_CENTERS, centres);
  // A cluster of a small share of the border is where the object (or its shadow) reaches the
  // border, not background: left out.
  std::vector<int> members(centres.rows, 0);
  for (int i = 0; i < labels.rows; ++i) ++members[labels.at<int>(i)];
  const int largest = *std::max_element(members.begin(), members.end());
  cv::Mat distance(lab.size(), CV_32FC1, cv::Scalar(std::numeric_limits<float>::infinity()));
  for (int k = 0; k < centres.rows; ++k) {
    if (members[k] < kMinClusterShare * samples.rows && members[k] < largest) continue;
    const cv::Vec3f centre(centres.at<float>(k, 0), centres.at<float>(k, 1),
                           centres.at<float>(k, 2));
    cv::Mat offset = lab - cv::Scalar(centre[0], centre[1], centre[2]);
    cv::Mat squared;
    cv::multiply(offset, offset, squared);
    cv::Mat sum;
    cv::transform(squared, sum, cv::Matx13f(1, 1, 1));
    cv::Mat norm;
    cv::sqrt(sum, norm);
    distance = cv::min(distance, norm);
  }
  return distance;
}

cv::Mat silhouetteFromImage(const cv::Mat& image, const SilhouetteConfig& config) {
  validate(config);
  if (image.empty() || image.depth() != CV_8U) {
    throw std::invalid_argument("silhouetteFromImage needs a non-empty 8-bit image");
  }
  return config.silhouette_method == "background" ? backgroundSilhouette(image, config)
                                                  : thresholdSilhouette(image, config);
}

std::vector<std::string> silhouetteWarnings(const std::vector<std::string>& names,
                                            const std::vector<cv::Mat>& masks) {
  if (names.size() != masks.size()) {
    throw std::invalid_argument("silhouetteWarnings: one name per mask");
  }
  std::vector<std::string> warnings;
  for (size_t i = 0; i < masks.size(); ++i) {
    const cv::Mat& mask = masks[i];
    if (mask.empty() || mask.type() != CV_8UC1) {
      throw std::invalid_argument("silhouetteWarnings: '" + names[i] + "' is not a CV_8UC1 mask");
    }
    const double share = static_cast<double>(cv::countNonZero(mask)) / mask.total();
    std::string reason;
    if (share == 0.0) {
      reason = "the silhouette is empty";
    } else if (share > 0.9) {
      reason = "the silhouette covers " + std::to_string(static_cast<int>(100 * share)) +
               " % of the image (the background taken for the object?)";
    } else if (cv::countNonZero(mask.row(0)) > 0 && cv::countNonZero(mask.row(mask.rows - 1)) > 0 &&
               cv::countNonZero(mask.col(0)) > 0 && cv::countNonZero(mask.col(mask.cols - 1)) > 0) {
      reason =
          "the silhouette touches all four image borders (the background taken for the "
          "object?)";
    }
    if (!reason.empty()) {
      warnings.push_back(names[i] + ": " + reason + "; leave the view out or give its mask");
    }
  }
  return warnings;
}

std::vector<std::string> runLengthSilhouetteWarnings(const std::vector<std::string>& names,
                                                     const std::vector<RunLengthMask>& masks) {
  if (names.size() != masks.size()) {
    throw std::invalid_argument("silhouetteWarnings: one name per mask");
  }
  std::vector<std::string> warnings;
  for (size_t i = 0; i < masks.size(); ++i) {
    const std::vector<std::string> found = silhouetteWarnings(
        std::vector<std::string>{names[i]}, std::vector<cv::Mat>{masks[i].decode()});
    warnings.insert(warnings.end(), found.begin(), found.end());
  }
  return warnings;
}

std::vector<std::string> disagreeingViewWarnings(const std::vector<std::string>& names,
                                                 const std::vector<double>& reprojection_iou) {
  if (names.size() != reprojection_iou.size()) {
    throw std::invalid_argument("disagreeingViewWarnings: one name per IoU");
  }
  std::vector<double> sorted = reprojection_iou;
  if (sorted.size() < 3) return {};
  std::sort(sorted.begin(), sorted.end());
  const double median = sorted[sorted.size() / 2];
  std::vector<std::string> warnings;
  for (size_t i = 0; i < names.size(); ++i) {
    const double iou = reprojection_iou[i];
    if (iou < 0.9 && iou < median - 0.1) {
      std::ostringstream message;
      message << names[i] << ": the hull reprojects onto its silhouette with IoU " << iou
              << ", the median view's " << median
              << ": its silhouette or camera disagrees with the others; leave the view out";
      warnings.push_back(message.str());
    }
  }
  return warnings;
}

}  // namespace sift_hull
