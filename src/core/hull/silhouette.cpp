#include "sift_hull/hull/silhouette.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <mutex>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "hull/silhouette_parts.h"
#include "sift_hull/limits.h"

#if defined(__SANITIZE_ADDRESS__)
#define SIFT_HULL_LEAK_CHECKS 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(leak_sanitizer)
#define SIFT_HULL_LEAK_CHECKS 1
#endif
#endif
#ifdef SIFT_HULL_LEAK_CHECKS
#include <sanitizer/lsan_interface.h>
#endif

namespace sift_hull {

namespace {

using silhouette_parts::disc;
using silhouette_parts::largeComponents;

/// The least share of the border a background colour cluster holds.
constexpr double kMinClusterShare = 0.005;
/// The border band's width as a share of the image's smaller side.
constexpr double kBorderFraction = 0.03;
/// The least colour distance (CIE Lab units) taken for the object, and the factor on the border
/// band's spread of distances the threshold lies above (see borderSpread).
constexpr float kMinObjectDistance = 3.0f;
constexpr float kSpreadFactor = 3.0f;
/// The largest spread of the border band's colour distances (CIE Lab) for which the border's
/// clusters alone make the silhouette; above it (a textured background) GrabCut does.
constexpr float kMaxClusteredSpread = 4.0f;
/// The longest image side GrabCut runs at (the silhouette is upsampled, its outline interpolated).
constexpr double kWorkingSidePx = 640.0;
constexpr int kGrabCutIterations = 5;
constexpr uint64_t kGrabCutSeed = 0x12345678;
/// The least IoU of the colour model's silhouette with GrabCut's for the two to be joined.
constexpr double kMinAgreement = 0.8;
/// The least area of a silhouette component, as a share of the largest one's.
constexpr double kMinComponentShare = 0.05;

/// Width of the border band of an image of `size`: `fraction` of its smaller side, at least 2
/// pixels and at most half that side.
int borderBand(cv::Size size, double fraction) {
  const int side = std::min(size.width, size.height);
  return std::min(std::max(2, static_cast<int>(fraction * side)), std::max(1, side / 2));
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

/// The spread of the border band's own colour distances (camera noise, the background's shading):
/// their 90th percentile, robust to the object reaching a part of the border.
float borderSpread(const cv::Mat& distance, int band) {
  std::vector<float> values;
  for (int v = 0; v < distance.rows; ++v) {
    const bool band_row = v < band || v >= distance.rows - band;
    const float* row = distance.ptr<float>(v);
    for (int u = 0; u < distance.cols; ++u) {
      if (band_row || u < band || u >= distance.cols - band) values.push_back(row[u]);
    }
  }
  const size_t rank = values.size() * 9 / 10;
  std::nth_element(values.begin(), values.begin() + rank, values.end());
  return std::isfinite(values[rank]) ? values[rank] : 0.0f;
}

/// Why a mask looks like the background taken for the object, or like nothing: empty, over 90 %
/// of the image, or touching all four borders; empty for a good one (silhouetteWarnings).
std::string suspectReason(const cv::Mat& mask) {
  const double share = static_cast<double>(cv::countNonZero(mask)) / mask.total();
  if (share == 0.0) return "the silhouette is empty";
  if (share > 0.9) {
    return "the silhouette covers " + std::to_string(static_cast<int>(100 * share)) +
           " % of the image (the background taken for the object?)";
  }
  if (cv::countNonZero(mask.row(0)) > 0 && cv::countNonZero(mask.row(mask.rows - 1)) > 0 &&
      cv::countNonZero(mask.col(0)) > 0 && cv::countNonZero(mask.col(mask.cols - 1)) > 0) {
    return "the silhouette touches all four image borders (the background taken for the object?)";
  }
  return "";
}

/// Isolated pixels and small components removed, a closing by a disc of erode_px, holes filled.
cv::Mat cleaned(cv::Mat mask, const SilhouetteConfig& config) {
  cv::morphologyEx(mask, mask, cv::MORPH_OPEN, disc(1));
  mask = largeComponents(mask);
  if (config.erode_px > 0) cv::morphologyEx(mask, mask, cv::MORPH_CLOSE, disc(config.erode_px));
  return filledHoles(mask);
}

/// GrabCut's silhouette of a BGR image, the border band as certain background: colour mixtures of
/// the object and the background and a graph cut that follows colour edges. It separates
/// backgrounds whose colours the border's clusters do not exhaust (texture). Run at most
/// kWorkingSidePx on the longest side, the result upsampled with its outline interpolated.
cv::Mat grabCutSilhouette(const cv::Mat& bgr) {
  const double scale = std::min(1.0, kWorkingSidePx / std::max(bgr.cols, bgr.rows));
  cv::Mat small = bgr;
  if (scale < 1.0) cv::resize(bgr, small, cv::Size(), scale, scale, cv::INTER_AREA);
  const int band = borderBand(small.size(), kBorderFraction);
  const cv::Rect inner(band, band, small.cols - 2 * band, small.rows - 2 * band);
  cv::Mat labels, background_model, object_model;
  cv::theRNG().state = kGrabCutSeed;  // its k-means: the same silhouette every run, every thread
  cv::grabCut(small, labels, inner, background_model, object_model, kGrabCutIterations,
              cv::GC_INIT_WITH_RECT);
  cv::Mat mask = (labels == cv::GC_FGD) | (labels == cv::GC_PR_FGD);
  if (scale < 1.0) {
    cv::Mat full;
    cv::resize(mask, full, bgr.size(), 0.0, 0.0, cv::INTER_LINEAR);
    mask = full > 127;
  }
  return mask;
}

/// The colour model's distances (backgroundDistance) and the spread of the border band's own
/// distances, by which the border is judged plain (<= kMaxClusteredSpread) or textured.
struct ColourModel {
  cv::Mat distance;
  float spread = 0.0f;
  bool plainBorder() const { return spread <= kMaxClusteredSpread; }
};

ColourModel colourModelOf(const cv::Mat& image) {
  ColourModel model;
  model.distance = backgroundDistance(image, kBorderFraction);
  model.spread = borderSpread(model.distance, borderBand(image.size(), kBorderFraction));
  return model;
}

/// The colour model's silhouette, cleaned.
cv::Mat colourModelSilhouette(const ColourModel& model, const SilhouetteConfig& config) {
  return cleaned(model.distance > std::max(kMinObjectDistance, kSpreadFactor * model.spread),
                 config);
}

cv::Mat backgroundSilhouette(const cv::Mat& image, const SilhouetteConfig& config,
                             bool* plain_border) {
  const ColourModel model = colourModelOf(image);
  const cv::Mat prior = colourModelSilhouette(model, config);
  if (plain_border != nullptr) *plain_border = model.plainBorder();
  // A border its clusters describe to within a few Lab units (a uniform or few-coloured
  // background, camera noise) is all the model needs.
  if (model.plainBorder()) return prior;
  cv::Mat bgr = image;
  if (image.channels() == 1) cv::cvtColor(image, bgr, cv::COLOR_GRAY2BGR);
  cv::Mat mask = grabCutSilhouette(bgr);
  // The colour model keeps the dark parts of an object on a dark background, which the mixtures
  // may give to the background; it is added where it agrees with the cut (IoU > kMinAgreement),
  // not where it has taken a textured background for the object.
  if (suspectReason(prior).empty()) {
    const double both = cv::countNonZero(mask & prior), either = cv::countNonZero(mask | prior);
    if (either > 0 && both / either > kMinAgreement) mask |= prior;
  }
  return cleaned(mask, config);
}

}  // namespace

namespace silhouette_parts {

namespace {

/// OpenCV builds its CIE Lab tables (about 5 MB) on the first conversion and keeps them for the
/// life of the process, held where LeakSanitizer does not find them, so it reports them as leaked
/// at exit. They are built here once, before any other conversion, with leak checking off for
/// this thread while it lasts; sift_hull's own allocations are checked as everywhere else.
void buildLabTablesOnce() {
  static std::once_flag once;
  std::call_once(once, [] {
#ifdef SIFT_HULL_LEAK_CHECKS
    __lsan::ScopedDisabler tables_kept_by_opencv;
#endif
    cv::Mat lab;
    cv::cvtColor(cv::Mat(1, 1, CV_32FC3, cv::Scalar::all(0.5)), lab, cv::COLOR_BGR2Lab);
  });
}

}  // namespace

cv::Mat labOf(const cv::Mat& image) {
  buildLabTablesOnce();
  cv::Mat bgr = image;
  if (image.channels() == 1) cv::cvtColor(image, bgr, cv::COLOR_GRAY2BGR);
  cv::Mat scaled, lab;
  bgr.convertTo(scaled, CV_32FC3, 1.0 / 255.0);
  cv::cvtColor(scaled, lab, cv::COLOR_BGR2Lab);
  return lab;
}

cv::Mat disc(int radius) {
  return cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * radius + 1, 2 * radius + 1));
}

/// The components of a mask holding at least kMinComponentShare of the largest one's area.
cv::Mat largeComponents(const cv::Mat& mask) {
  cv::Mat labels, stats, centroids;
  const int count = cv::connectedComponentsWithStats(mask, labels, stats, centroids, 8, CV_32S);
  int largest = 0;
  for (int i = 1; i < count; ++i) largest = std::max(largest, stats.at<int>(i, cv::CC_STAT_AREA));
  std::vector<uint8_t> keep(count, 0);
  for (int i = 1; i < count; ++i) {
    keep[i] = stats.at<int>(i, cv::CC_STAT_AREA) >= kMinComponentShare * largest ? 255 : 0;
  }
  cv::Mat kept(mask.size(), CV_8UC1);
  for (int v = 0; v < mask.rows; ++v) {
    const int* label = labels.ptr<int>(v);
    uint8_t* out = kept.ptr<uint8_t>(v);
    for (int u = 0; u < mask.cols; ++u) out[u] = keep[label[u]];
  }
  return kept;
}

}  // namespace silhouette_parts

cv::Mat backgroundDistance(const cv::Mat& image, double border_fraction) {
  if (image.empty() || image.depth() != CV_8U || (image.channels() != 1 && image.channels() != 3)) {
    throw std::invalid_argument("backgroundDistance needs a non-empty 8-bit grey or BGR image");
  }
  const cv::Mat lab = silhouette_parts::labOf(image);
  const cv::Mat samples = borderSamples(lab, borderBand(lab.size(), border_fraction), 4000);
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

cv::Mat plainBackgroundSilhouette(const cv::Mat& image, const SilhouetteConfig& config) {
  validate(config);
  if (image.empty() || image.depth() != CV_8U) {
    throw std::invalid_argument("plainBackgroundSilhouette needs a non-empty 8-bit image");
  }
  const ColourModel model = colourModelOf(image);
  return model.plainBorder() ? colourModelSilhouette(model, config) : cv::Mat();
}

cv::Mat silhouetteFromImage(const cv::Mat& image, const SilhouetteConfig& config,
                            bool* plain_border) {
  validate(config);
  if (image.empty() || image.depth() != CV_8U) {
    throw std::invalid_argument("silhouetteFromImage needs a non-empty 8-bit image");
  }
  if (plain_border != nullptr) *plain_border = false;
  return config.silhouette_method != "threshold" ? backgroundSilhouette(image, config, plain_border)
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
    const std::string reason = suspectReason(mask);
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
