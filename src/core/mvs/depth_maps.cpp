// Photo carving's depth maps: each view reduced to the configured scale in ideal pixels, its
// neighbours chosen by angle, the hull's depth range per pixel from the occupied leaves, a
// fronto-parallel plane sweep scored by the normalised cross-correlation (NCC) of grey patches
// with the best of the neighbours, and the geometric consistency between the views' depth maps.

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>

#include "mvs/mvs_internal.h"

namespace sift_hull {
namespace detail {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

/// camera's projection with K scaled by (sx, sy) about pixel centres: u' = sx (u + 0.5) - 0.5.
PinholeCamera scaledIdeal(const PinholeCamera& camera, double sx, double sy) {
  Eigen::Matrix3d S;
  S << sx, 0.0, 0.5 * (sx - 1.0), 0.0, sy, 0.5 * (sy - 1.0), 0.0, 0.0, 1.0;
  if (!camera.improper()) return PinholeCamera(S * camera.K(), camera.R(), camera.t());
  return PinholeCamera(S * camera.K(), -camera.R(), -camera.t()).negated();
}

cv::Mat greyOf(const cv::Mat& image) {
  cv::Mat grey;
  if (image.channels() == 1) {
    grey = image;
  } else if (image.channels() == 3) {
    cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  } else if (image.channels() == 4) {
    cv::cvtColor(image, grey, cv::COLOR_BGRA2GRAY);
  } else {
    throw std::invalid_argument("photo carving: an image of " + std::to_string(image.channels()) +
                                " channels (1, 3 or 4 are read)");
  }
  if (grey.depth() != CV_8U && grey.depth() != CV_16U) {
    throw std::invalid_argument("photo carving: an image that is not 8 or 16 bits per channel");
  }
  cv::Mat out;
  grey.convertTo(out, CV_32F, grey.depth() == CV_8U ? 1.0 / 255.0 : 1.0 / 65535.0);
  return out;
}

}  // namespace

double depthMapScale(const PinholeCamera& camera, const Eigen::Vector3d& centre_W, double voxel_m,
                     const PhotoCarveConfig& config) {
  const double depth_m = camera.depth(centre_W);
  const double focal_px = 0.5 * (std::abs(camera.K()(0, 0)) + std::abs(camera.K()(1, 1)));
  const double footprint_px = depth_m > 0.0 ? focal_px * voxel_m / depth_m : 0.0;
  if (!(footprint_px > 0.0) || !std::isfinite(footprint_px)) return config.photo_image_scale;
  return std::min(config.photo_image_scale,
                  std::max(config.photo_voxel_px / footprint_px, 1.0 / 64));
}

ReducedView reducedView(const PinholeCamera& camera, const cv::Mat& image, const cv::Mat& mask,
                        double scale, int patch_radius_px) {
  if (image.empty() || mask.empty() || image.size() != mask.size() || mask.type() != CV_8UC1) {
    throw std::invalid_argument(
        "photo carving: an empty image, or a silhouette that is not CV_8UC1 of the image's size");
  }
  const cv::Size size(std::max(1, static_cast<int>(std::lround(image.cols * scale))),
                      std::max(1, static_cast<int>(std::lround(image.rows * scale))));
  const double sx = static_cast<double>(size.width) / image.cols;
  const double sy = static_cast<double>(size.height) / image.rows;
  ReducedView view;
  view.camera = scaledIdeal(camera, sx, sy);
  cv::Mat inside;
  cv::resize(greyOf(image), view.grey, size, 0.0, 0.0, cv::INTER_AREA);
  cv::resize(mask > 0, inside, size, 0.0, 0.0, cv::INTER_AREA);
  inside = inside >= 128;
  if (camera.distorted()) {  // each ideal pixel of the reduced view from its raw pixel
    cv::Mat map_x(size, CV_32FC1), map_y(size, CV_32FC1);
    for (int v = 0; v < size.height; ++v) {
      for (int u = 0; u < size.width; ++u) {
        const Eigen::Vector2d ideal((u - 0.5 * (sx - 1.0)) / sx, (v - 0.5 * (sy - 1.0)) / sy);
        const Eigen::Vector2d raw = camera.distortPixel(ideal);
        map_x.at<float>(v, u) = static_cast<float>(sx * raw.x() + 0.5 * (sx - 1.0));
        map_y.at<float>(v, u) = static_cast<float>(sy * raw.y() + 0.5 * (sy - 1.0));
      }
    }
    cv::remap(view.grey, view.grey, map_x, map_y, cv::INTER_LINEAR, cv::BORDER_CONSTANT, 0.0);
    cv::remap(inside, inside, map_x, map_y, cv::INTER_NEAREST, cv::BORDER_CONSTANT, 0);
  }
  const int side = 2 * patch_radius_px + 1;
  cv::erode(inside, view.inside, cv::Mat::ones(side, side, CV_8U), cv::Point(-1, -1), 1,
            cv::BORDER_CONSTANT, 0);
  return view;
}

std::vector<std::vector<uint32_t>> chooseNeighbours(const std::vector<PinholeCamera>& cameras,
                                                    const Eigen::Vector3d& centre_W, int count,
                                                    double max_angle_deg) {
  std::vector<Eigen::Vector3d> sight;
  for (const PinholeCamera& camera : cameras) {
    sight.push_back((camera.centre() - centre_W).normalized());
  }
  std::vector<std::vector<uint32_t>> neighbours(cameras.size());
  for (size_t v = 0; v < cameras.size(); ++v) {
    std::vector<std::pair<double, uint32_t>> by_angle;
    for (size_t n = 0; n < cameras.size(); ++n) {
      if (n == v) continue;
      const double angle_deg =
          std::acos(std::clamp(sight[v].dot(sight[n]), -1.0, 1.0)) * 180.0 / M_PI;
      // A view from (almost) the same place gives no depth: its planes all look alike.
      if (angle_deg >= 1.0 && angle_deg <= max_angle_deg) {
        by_angle.emplace_back(angle_deg, static_cast<uint32_t>(n));
      }
    }
    std::sort(by_angle.begin(), by_angle.end());
    for (size_t i = 0; i < by_angle.size() && static_cast<int>(i) < count; ++i) {
      neighbours[v].push_back(by_angle[i].second);
    }
  }
  return neighbours;
}

DepthRange hullDepthRange(const std::vector<HullCell>& occupied, const HullCube& cube,
                          const PinholeCamera& camera, cv::Size size) {
  DepthRange range;
  range.near_m = cv::Mat(size, CV_32FC1, cv::Scalar(kNaN));
  range.far_m = cv::Mat(size, CV_32FC1, cv::Scalar(kNaN));
  double min_m = std::numeric_limits<double>::infinity(), max_m = 0.0;
  for (const HullCell& cell : occupied) {
    const double edge_m = cube.resolution_m * static_cast<double>(1 << (cube.depth - cell.depth));
    const Eigen::Vector3d corner_W = cube.origin_W() + cell.index.cast<double>() * edge_m;
    double u0 = std::numeric_limits<double>::infinity(), v0 = u0, u1 = -u0, v1 = -u0;
    double near = u0, far = 0.0;
    bool behind = false;
    for (int c = 0; c < 8; ++c) {
      const Eigen::Vector3d X = corner_W + edge_m * Eigen::Vector3d(c & 1, (c >> 1) & 1, c >> 2);
      const double depth = camera.depth(X);
      if (!(depth > 0.0)) behind = true;
      const Eigen::Vector2d px = camera.projectIdeal(X);
      u0 = std::min(u0, px.x()), u1 = std::max(u1, px.x());
      v0 = std::min(v0, px.y()), v1 = std::max(v1, px.y());
      near = std::min(near, depth), far = std::max(far, depth);
    }
    if (behind) continue;  // a camera inside the hull sees no range there
    const int first_u = std::max(0, static_cast<int>(std::floor(u0)));
    const int last_u = std::min(size.width - 1, static_cast<int>(std::ceil(u1)));
    const int first_v = std::max(0, static_cast<int>(std::floor(v0)));
    const int last_v = std::min(size.height - 1, static_cast<int>(std::ceil(v1)));
    if (first_u > last_u || first_v > last_v) continue;
    min_m = std::min(min_m, near), max_m = std::max(max_m, far);
    for (int v = first_v; v <= last_v; ++v) {
      float* near_row = range.near_m.ptr<float>(v);
      float* far_row = range.far_m.ptr<float>(v);
      for (int u = first_u; u <= last_u; ++u) {
        if (!(near_row[u] <= near)) near_row[u] = static_cast<float>(near);
        if (!(far_row[u] >= far)) far_row[u] = static_cast<float>(far);
      }
    }
  }
  if (max_m > 0.0) range.min_m = min_m, range.max_m = max_m;
  return range;
}

void sweepDepth(const std::vector<ReducedView>& views, uint32_t view,
                const std::vector<uint32_t>& neighbours, const DepthRange& range,
                const PhotoCarveConfig& config, double voxel_m, cv::Mat* depth_m, cv::Mat* ncc,
                size_t* sweeps) {
  const ReducedView& ref = views[view];
  *depth_m = cv::Mat(ref.grey.size(), CV_32FC1, cv::Scalar(kNaN));
  *ncc = cv::Mat(ref.grey.size(), CV_32FC1, cv::Scalar(kNaN));
  const int best = std::min<int>(config.photo_best_neighbours, static_cast<int>(neighbours.size()));
  if (best < 1 || !(range.max_m > range.min_m) || cv::countNonZero(ref.inside) == 0) return;
  // The sweep covers the box of the pixels inside the silhouette and their patches.
  const int radius = config.photo_patch_radius_px;
  cv::Rect roi = cv::boundingRect(ref.inside);
  roi = cv::Rect(roi.x - radius, roi.y - radius, roi.width + 2 * radius, roi.height + 2 * radius) &
        cv::Rect(0, 0, ref.grey.cols, ref.grey.rows);
  const cv::Size size = roi.size();
  const cv::Mat grey = ref.grey(roi), inside_roi = ref.inside(roi);
  const cv::Mat near_roi = range.near_m(roi), far_roi = range.far_m(roi);
  const cv::Size patch(2 * radius + 1, 2 * radius + 1);
  const auto box = [&](const cv::Mat& src) {
    cv::Mat out;
    cv::boxFilter(src, out, CV_32F, patch, cv::Point(-1, -1), true, cv::BORDER_REPLICATE);
    return out;
  };
  const cv::Mat ref_mean = box(grey);
  const cv::Mat ref_var = box(grey.mul(grey)) - ref_mean.mul(ref_mean);
  const float min_var = static_cast<float>(config.photo_min_patch_std * config.photo_min_patch_std);
  // The planes, evenly in inverse depth, a little beyond the hull's range.
  const double margin_m = 2.0 * voxel_m;
  const double inv_near = 1.0 / std::max(range.min_m - margin_m, 1e-9);
  const double inv_far = 1.0 / (range.max_m + margin_m);
  const int planes = config.photo_depth_planes;
  const double inv_step = (inv_near - inv_far) / std::max(planes - 1, 1);
  Eigen::Matrix3d from_roi = Eigen::Matrix3d::Identity();  // ROI pixels to the view's
  from_roi(0, 2) = roi.x, from_roi(1, 2) = roi.y;
  const Eigen::Matrix3d K_ref_inv = ref.camera.K().inverse() * from_roi;
  std::vector<cv::Mat> scores(neighbours.size());
  cv::Mat best_score(size, CV_32FC1, cv::Scalar(-2.0f)), prev_score(size, CV_32FC1, kNaN);
  cv::Mat best_prev(size, CV_32FC1, kNaN), best_next(size, CV_32FC1, kNaN);
  cv::Mat best_plane(size, CV_32SC1, cv::Scalar(-1));
  std::vector<float> values(neighbours.size());
  for (int k = 0; k < planes; ++k) {
    const double plane_m = 1.0 / (inv_far + k * inv_step);
    for (size_t i = 0; i < neighbours.size(); ++i) {
      const ReducedView& other = views[neighbours[i]];
      // X_other = R_rel X_ref + t_rel, and on the plane z_ref = d: H = K (R_rel + t_rel e3^T / d).
      const Eigen::Matrix3d R_rel = other.camera.R() * ref.camera.R().transpose();
      const Eigen::Vector3d t_rel = other.camera.t() - R_rel * ref.camera.t();
      Eigen::Matrix3d G = R_rel;
      G.col(2) += t_rel / plane_m;
      const Eigen::Matrix3d H = other.camera.K() * G * K_ref_inv;
      cv::Mat H_cv(3, 3, CV_64F);
      for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) H_cv.at<double>(r, c) = H(r, c);
      }
      cv::Mat warped;
      cv::warpPerspective(other.grey, warped, H_cv, size, cv::INTER_LINEAR | cv::WARP_INVERSE_MAP,
                          cv::BORDER_CONSTANT, 0.0);
      const cv::Mat mean = box(warped);
      const cv::Mat var = box(warped.mul(warped)) - mean.mul(mean);
      const cv::Mat cross = box(grey.mul(warped)) - ref_mean.mul(mean);
      // A patch is compared where it lies inside the other image (its centre a radius from the
      // border: the plane's map is close to a similarity over a patch).
      const double u_max = other.grey.cols - 1.0 - radius, v_max = other.grey.rows - 1.0 - radius;
      cv::Mat& score = scores[i];
      score.create(size, CV_32FC1);
      for (int v = 0; v < size.height; ++v) {
        const float *c = cross.ptr<float>(v), *a = ref_var.ptr<float>(v), *b = var.ptr<float>(v);
        float* s = score.ptr<float>(v);
        Eigen::Vector3d x = H.col(1) * v + H.col(2);
        for (int u = 0; u < size.width; ++u, x += H.col(0)) {
          const double pu = x.x() / x.z(), pv = x.y() / x.z();
          const bool seen =
              x.z() > 0.0 && pu >= radius && pv >= radius && pu <= u_max && pv <= v_max;
          s[u] = (seen && b[u] > min_var && a[u] > min_var) ? c[u] / std::sqrt(a[u] * b[u]) : kNaN;
        }
      }
      ++*sweeps;
    }
    for (int v = 0; v < size.height; ++v) {
      const float* near = near_roi.ptr<float>(v);
      const float* far = far_roi.ptr<float>(v);
      const uint8_t* inside = inside_roi.ptr<uint8_t>(v);
      float* top = best_score.ptr<float>(v);
      float* prev = prev_score.ptr<float>(v);
      float *top_prev = best_prev.ptr<float>(v), *top_next = best_next.ptr<float>(v);
      int* top_plane = best_plane.ptr<int>(v);
      for (int u = 0; u < size.width; ++u) {
        float s = kNaN;
        if (inside[u] && plane_m >= near[u] - margin_m && plane_m <= far[u] + margin_m) {
          for (size_t i = 0; i < neighbours.size(); ++i) values[i] = scores[i].ptr<float>(v)[u];
          s = bestMean(values.data(), static_cast<int>(values.size()), best);
        }
        if (top_plane[u] == k - 1) top_next[u] = s;
        if (s > top[u]) top[u] = s, top_plane[u] = k, top_prev[u] = prev[u], top_next[u] = kNaN;
        prev[u] = s;
      }
    }
  }
  for (int v = 0; v < size.height; ++v) {
    for (int u = 0; u < size.width; ++u) {
      const float s = best_score.at<float>(v, u);
      if (best_plane.at<int>(v, u) < 0 || ref_var.at<float>(v, u) <= min_var) continue;
      // A parabola through the scores of the planes on either side, in inverse depth.
      double offset = 0.0;
      const float before = best_prev.at<float>(v, u), after = best_next.at<float>(v, u);
      const double curvature = static_cast<double>(before) - 2.0 * s + after;
      if (std::isfinite(curvature) && curvature < 0.0) {
        offset = std::clamp(0.5 * (before - after) / curvature, -0.5, 0.5);
      }
      const double inv = inv_far + (best_plane.at<int>(v, u) + offset) * inv_step;
      depth_m->at<float>(v + roi.y, u + roi.x) = static_cast<float>(1.0 / inv);
      ncc->at<float>(v + roi.y, u + roi.x) = s;
    }
  }
}

namespace {

/// Whether one of the (up to) four pixels around `px` holds a depth within tolerance_m of
/// expected_m: the pixel grid, not the surface, decides which of them the point falls on, and on
/// a slanted surface the nearest one alone can be a voxel or more off.
bool agreesNearby(const cv::Mat& depth_m, const Eigen::Vector2d& px, double expected_m,
                  double tolerance_m) {
  const double u = std::floor(px.x()), v = std::floor(px.y());
  if (!(u >= -1.0 && v >= -1.0 && u < depth_m.cols && v < depth_m.rows)) return false;
  for (int dv = 0; dv < 2; ++dv) {
    for (int du = 0; du < 2; ++du) {
      const int pu = static_cast<int>(u) + du, pv = static_cast<int>(v) + dv;
      if (pu < 0 || pv < 0 || pu >= depth_m.cols || pv >= depth_m.rows) continue;
      if (std::abs(depth_m.at<float>(pv, pu) - expected_m) <= tolerance_m) return true;  // NaN: no
    }
  }
  return false;
}

}  // namespace

cv::Mat consistentDepth(const std::vector<ViewDepth>& depths, uint32_t view,
                        const PhotoCarveConfig& config, double voxel_m) {
  const ViewDepth& ref = depths[view];
  cv::Mat kept(ref.depth_m.size(), CV_32FC1, cv::Scalar(kNaN));
  const double tolerance_m = config.photo_consistency_voxels * voxel_m;
  for (int v = 0; v < kept.rows; ++v) {
    for (int u = 0; u < kept.cols; ++u) {
      const float depth = ref.depth_m.at<float>(v, u);
      if (std::isnan(depth)) continue;
      const Eigen::Vector3d X = ref.camera.backProject(Eigen::Vector2d(u, v), depth);
      int agree = 0;
      for (uint32_t n : ref.neighbours) {
        const ViewDepth& other = depths[n];
        const double expected = other.camera.depth(X);
        if (!(expected > 0.0)) continue;
        agree += agreesNearby(other.depth_m, other.camera.projectIdeal(X), expected, tolerance_m);
      }
      if (agree >= config.photo_min_consistent_views) kept.at<float>(v, u) = depth;
    }
  }
  return kept;
}

std::vector<HullCell> occupiedLeaves(const VisualHull& hull) {
  std::vector<HullCell> leaves;
  hull.forEachLeaf([&](const HullCell& cell) {
    if (isOccupied(cell)) leaves.push_back(cell);
  });
  return leaves;
}

}  // namespace detail
}  // namespace sift_hull
