// Dense matching along epipolar lines: a left pixel's line of sight is walked through the hull's
// cells for the depths it spans, each depth's patch is mapped into the right view by the affine
// map of a plane facing the left camera there, and the NCC's clear best is kept when the search
// back from the right view returns to the left pixel.

#include "sift_hull/refine/dense_matching.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/parallel.h"

namespace sift_hull {
namespace {

/// Most depths sampled along one epipolar line.
constexpr size_t kMaxSamples = 4096;

/// A line of sight: X(d) = centre + d * direction, d the depth along the optical axis.
struct Ray {
  Eigen::Vector3d centre, direction;
  Eigen::Vector3d at(double depth) const { return centre + depth * direction; }
};

std::optional<Ray> rayThrough(const PinholeCamera& camera, const Eigen::Vector2d& raw_px) {
  const std::optional<Eigen::Vector2d> ideal = camera.undistortPixel(raw_px);
  if (!ideal) return std::nullopt;
  return Ray{camera.centre(),
             camera.R().transpose() * (camera.K().inverse() * ideal->homogeneous())};
}

/// The depths between which the ray runs through occupied cells of the hull (first entry, last
/// exit), walking leaf by leaf; empty when it misses them.
std::optional<std::pair<double, double>> hullSpan(const VisualHull& hull, const Ray& ray) {
  const Box3d box = hull.cube().box();
  double d0 = 1e-9, d1 = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 3; ++a) {
    const double o = ray.centre[a], v = ray.direction[a];
    if (std::abs(v) < 1e-15) {
      if (o < box.min_W[a] || o > box.max_W[a]) return std::nullopt;
      continue;
    }
    double t0 = (box.min_W[a] - o) / v, t1 = (box.max_W[a] - o) / v;
    if (t0 > t1) std::swap(t0, t1);
    d0 = std::max(d0, t0), d1 = std::min(d1, t1);
  }
  if (!(d0 < d1)) return std::nullopt;
  const double nudge = 1e-4 * hull.cube().resolution_m / ray.direction.norm();
  double first = -1.0, last = -1.0;
  for (double d = d0 + nudge; d < d1;) {
    const HullCell cell = hull.leafAt(ray.at(d));
    const double edge = hull.cube().edge_m() / static_cast<double>(1 << cell.depth);
    const Eigen::Vector3d lo = hull.cube().origin_W() + edge * cell.index.cast<double>();
    double exit = d1;
    for (int a = 0; a < 3; ++a) {
      const double v = ray.direction[a];
      if (std::abs(v) < 1e-15) continue;
      const double side = v > 0.0 ? lo[a] + edge : lo[a];
      exit = std::min(exit, (side - ray.centre[a]) / v);
    }
    if (cell.state != CellState::kOut) {
      if (first < 0.0) first = d;
      last = exit;
    }
    d = std::max(exit, d) + nudge;
  }
  if (first < 0.0) return std::nullopt;
  return std::make_pair(first, last);
}

float bilinear(const cv::Mat& image, double x, double y) {
  const int x0 = static_cast<int>(x), y0 = static_cast<int>(y);
  const int x1 = std::min(x0 + 1, image.cols - 1), y1 = std::min(y0 + 1, image.rows - 1);
  const float fx = static_cast<float>(x - x0), fy = static_cast<float>(y - y0);
  const float* r0 = image.ptr<float>(y0);
  const float* r1 = image.ptr<float>(y1);
  const float top = r0[x0] + fx * (r0[x1] - r0[x0]);
  const float bottom = r1[x0] + fx * (r1[x1] - r1[x0]);
  return top + fy * (bottom - top);
}

bool insideImage(const cv::Mat& image, const Eigen::Vector2d& px) {
  return px.x() >= 0.0 && px.y() >= 0.0 && px.x() <= image.cols - 1.0 && px.y() <= image.rows - 1.0;
}

/// Whether the patch around a pixel (inside the image) lies inside the silhouette.
bool insideSilhouette(const DenseView& view, const Eigen::Vector2d& px) {
  const int u = std::min(static_cast<int>(std::lround(px.x())), view.inside.cols - 1);
  const int v = std::min(static_cast<int>(std::lround(px.y())), view.inside.rows - 1);
  return view.inside.at<uint8_t>(v, u) != 0;
}

/// The best match of a reference pixel along its line of sight in the other view.
struct RayMatch {
  Eigen::Vector3d X_W;
  double ncc;
};

class RaySearch {
 public:
  RaySearch(const DenseView& reference, const PinholeCamera& reference_camera,
            const DenseView& target, const PinholeCamera& target_camera, const VisualHull& hull,
            const DenseMatchConfig& config)
      : reference_(reference),
        reference_camera_(reference_camera),
        target_(target),
        target_camera_(target_camera),
        hull_(hull),
        config_(config) {}

  std::optional<RayMatch> search(const Eigen::Vector2d& px) const {
    const int r = config_.patch_radius_px;
    const Eigen::Vector2d lo = px - Eigen::Vector2d::Constant(r);
    const Eigen::Vector2d hi = px + Eigen::Vector2d::Constant(r);
    if (!insideImage(reference_.grey, lo) || !insideImage(reference_.grey, hi)) return std::nullopt;
    if (!insideSilhouette(reference_, px)) return std::nullopt;
    std::vector<float> patch;
    if (!normalisedPatch(px, &patch)) return std::nullopt;
    const std::optional<Ray> ray = rayThrough(reference_camera_, px);
    const std::optional<Ray> ray_u = rayThrough(reference_camera_, px + Eigen::Vector2d(1, 0));
    const std::optional<Ray> ray_v = rayThrough(reference_camera_, px + Eigen::Vector2d(0, 1));
    if (!ray || !ray_u || !ray_v) return std::nullopt;
    const std::optional<std::pair<double, double>> span = hullSpan(hull_, *ray);
    if (!span) return std::nullopt;
    const auto [near, far] = *span;
    if (target_camera_.depth(ray->at(near)) <= 0.0 || target_camera_.depth(ray->at(far)) <= 0.0) {
      return std::nullopt;
    }
    const double line_px =
        (target_camera_.project(ray->at(far)) - target_camera_.project(ray->at(near))).norm();
    if (!std::isfinite(line_px)) return std::nullopt;
    const size_t n = std::min(kMaxSamples, static_cast<size_t>(std::ceil(1.5 * line_px)) + 2);
    const double step = (far - near) / static_cast<double>(n - 1);
    std::vector<double> ncc(n);
    for (size_t k = 0; k < n; ++k) {
      const double d = near + step * static_cast<double>(k);
      ncc[k] = correlation(patch, ray->at(d), ray_u->at(d), ray_v->at(d));
    }
    const size_t best = static_cast<size_t>(std::max_element(ncc.begin(), ncc.end()) - ncc.begin());
    if (!(ncc[best] >= config_.min_ncc)) return std::nullopt;
    const double spacing_px = std::max(line_px / static_cast<double>(n - 1), 1e-6);
    const size_t exclusion = static_cast<size_t>(std::ceil((r + 1.0) / spacing_px));
    for (size_t k = 0; k < n; ++k) {
      const bool peak = (k == 0 || ncc[k] >= ncc[k - 1]) && (k + 1 == n || ncc[k] >= ncc[k + 1]);
      const size_t gap = k > best ? k - best : best - k;
      if (peak && gap > exclusion && ncc[best] - ncc[k] < config_.min_ncc_margin) {
        return std::nullopt;
      }
    }
    double offset = 0.0;
    if (best > 0 && best + 1 < n) {
      const double a = ncc[best - 1], b = ncc[best], c = ncc[best + 1];
      const double curvature = a - 2.0 * b + c;
      if (curvature < 0.0) offset = std::clamp(0.5 * (a - c) / curvature, -0.5, 0.5);
    }
    return RayMatch{ray->at(near + step * (static_cast<double>(best) + offset)), ncc[best]};
  }

 private:
  /// The reference patch, mean removed and scaled to unit norm; false when too flat.
  bool normalisedPatch(const Eigen::Vector2d& px, std::vector<float>* patch) const {
    const int r = config_.patch_radius_px;
    patch->clear();
    double sum = 0.0;
    for (int j = -r; j <= r; ++j) {
      for (int i = -r; i <= r; ++i) {
        patch->push_back(bilinear(reference_.grey, px.x() + i, px.y() + j));
        sum += patch->back();
      }
    }
    const double mean = sum / static_cast<double>(patch->size());
    double squares = 0.0;
    for (float& value : *patch) {
      value = static_cast<float>(value - mean);
      squares += static_cast<double>(value) * value;
    }
    const double stddev = std::sqrt(squares / static_cast<double>(patch->size()));
    if (!(stddev >= config_.min_patch_std)) return false;
    const float scale = static_cast<float>(1.0 / std::sqrt(squares));
    for (float& value : *patch) value *= scale;
    return true;
  }

  /// NCC of the reference patch with the target image around the projection of X, the patch's
  /// axes mapped through X_u and X_v (the points one pixel along u and v at the same depth);
  /// -1 where the patch leaves the target image or lies behind its camera.
  double correlation(const std::vector<float>& patch, const Eigen::Vector3d& X,
                     const Eigen::Vector3d& X_u, const Eigen::Vector3d& X_v) const {
    if (target_camera_.depth(X) <= 0.0) return -1.0;
    const int r = config_.patch_radius_px;
    const Eigen::Vector2d c = target_camera_.project(X);
    const Eigen::Vector2d du = target_camera_.project(X_u) - c;
    const Eigen::Vector2d dv = target_camera_.project(X_v) - c;
    const Eigen::Vector2d reach = static_cast<double>(r) * (du.cwiseAbs() + dv.cwiseAbs());
    if (!insideImage(target_.grey, c - reach) || !insideImage(target_.grey, c + reach)) return -1.0;
    if (!insideSilhouette(target_, c)) return -1.0;
    double cross = 0.0, sum = 0.0, squares = 0.0;
    size_t k = 0;
    for (int j = -r; j <= r; ++j) {
      for (int i = -r; i <= r; ++i) {
        const Eigen::Vector2d p = c + static_cast<double>(i) * du + static_cast<double>(j) * dv;
        const double value = bilinear(target_.grey, p.x(), p.y());
        cross += patch[k++] * value;
        sum += value;
        squares += value * value;
      }
    }
    const double variance = squares - sum * sum / static_cast<double>(patch.size());
    if (!(variance > 1e-12)) return -1.0;
    return cross / std::sqrt(variance);
  }

  const DenseView& reference_;
  const PinholeCamera& reference_camera_;
  const DenseView& target_;
  const PinholeCamera& target_camera_;
  const VisualHull& hull_;
  const DenseMatchConfig& config_;
};

void checkView(const DenseView& view, const char* which) {
  if (view.grey.empty() || view.grey.type() != CV_32FC1 || view.inside.type() != CV_8UC1 ||
      view.inside.size() != view.grey.size()) {
    throw std::invalid_argument(std::string("denseMatches: the ") + which +
                                " view is not one of denseMatchingView");
  }
}

}  // namespace

void validate(const DenseMatchConfig& config) {
  const auto fail = [](const std::string& what) {
    throw std::invalid_argument("DenseMatchConfig::" + what);
  };
  if (config.grid_step_px < 0 || config.grid_step_px > 1000) {
    fail("grid_step_px must be in [0, 1000] (0: off)");
  }
  if (config.patch_radius_px < 1 || config.patch_radius_px > 15) {
    fail("patch_radius_px must be in [1, 15]");
  }
  if (!(config.min_ncc > -1.0 && config.min_ncc <= 1.0)) fail("min_ncc must be in (-1, 1]");
  if (!(config.min_ncc_margin >= 0.0 && config.min_ncc_margin <= 2.0)) {
    fail("min_ncc_margin must be in [0, 2]");
  }
  if (!(config.min_patch_std >= 0.0 && config.min_patch_std <= 1.0)) {
    fail("min_patch_std must be in [0, 1]");
  }
  if (!(config.max_round_trip_px > 0.0 && std::isfinite(config.max_round_trip_px))) {
    fail("max_round_trip_px must be finite and > 0");
  }
}

DenseView denseMatchingView(const cv::Mat& image, const cv::Mat& mask, int patch_radius_px) {
  if (image.empty()) throw std::invalid_argument("denseMatchingView: empty image");
  const int depth = image.depth(), channels = image.channels();
  if ((depth != CV_8U && depth != CV_16U) || (channels != 1 && channels != 3 && channels != 4)) {
    throw std::invalid_argument("denseMatchingView: needs CV_8U or CV_16U with 1, 3 or 4 channels");
  }
  if (mask.type() != CV_8UC1 || mask.size() != image.size()) {
    throw std::invalid_argument(
        "denseMatchingView: the silhouette must be CV_8UC1 of the image's size");
  }
  DenseMatchConfig config;
  config.patch_radius_px = patch_radius_px;
  validate(config);
  cv::Mat grey = image;
  if (channels == 3) cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  if (channels == 4) cv::cvtColor(image, grey, cv::COLOR_BGRA2GRAY);
  DenseView view;
  grey.convertTo(view.grey, CV_32F, depth == CV_8U ? 1.0 / 255.0 : 1.0 / 65535.0);
  const int side = 2 * patch_radius_px + 1;
  cv::erode(mask != 0, view.inside, cv::getStructuringElement(cv::MORPH_RECT, {side, side}),
            cv::Point(-1, -1), 1, cv::BORDER_CONSTANT, cv::Scalar(0));
  return view;
}

PairMatches denseMatches(const DenseView& left_image, const DenseView& right_image,
                         const PinholeCamera& left, const PinholeCamera& right, uint32_t left_view,
                         uint32_t right_view, const VisualHull& hull,
                         const DenseMatchConfig& config, int threads) {
  validate(config);
  checkView(left_image, "left");
  checkView(right_image, "right");
  PairMatches result;
  result.left_view = left_view, result.right_view = right_view;
  if (config.grid_step_px == 0 || hull.isEmpty()) return result;
  const RaySearch forward(left_image, left, right_image, right, hull, config);
  const RaySearch back(right_image, right, left_image, left, hull, config);
  const int step = config.grid_step_px;
  const size_t rows = static_cast<size_t>((left_image.grey.rows + step - 1) / step);
  std::vector<PairMatches> by_row(rows);
  detail::parallelFor(rows, std::max(threads, 1), [&](size_t row) {
    const double v = static_cast<double>(row) * step;
    for (int u = 0; u < left_image.grey.cols; u += step) {
      const Eigen::Vector2d left_px(u, v);
      const std::optional<RayMatch> there = forward.search(left_px);
      if (!there) continue;
      const Eigen::Vector2d right_px = right.project(there->X_W);
      const std::optional<RayMatch> home = back.search(right_px);
      if (!home || left.depth(home->X_W) <= 0.0) continue;
      if ((left.project(home->X_W) - left_px).norm() > config.max_round_trip_px) continue;
      by_row[row].left_px.push_back(left_px);
      by_row[row].right_px.push_back(right_px);
    }
  });
  for (const PairMatches& row : by_row) {
    result.left_px.insert(result.left_px.end(), row.left_px.begin(), row.left_px.end());
    result.right_px.insert(result.right_px.end(), row.right_px.begin(), row.right_px.end());
  }
  return result;
}

}  // namespace sift_hull
