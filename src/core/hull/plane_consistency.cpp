// The support plane's pixels by its homographies between the views (hull/plane_consistency.h).

#include "hull/plane_consistency.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <utility>

namespace sift_hull {
namespace view_prior {
namespace {

/// Working pixels of view `camera` of the plane point O + a e1 + b e2, as (a, b, 1) -> pixel.
Eigen::Matrix3d planeToPixels(const PinholeCamera& camera, const PixelScale& scale,
                              const Eigen::Vector3d& origin, const Eigen::Vector3d& e1,
                              const Eigen::Vector3d& e2) {
  Eigen::Matrix3d columns;
  columns.col(0) = camera.R() * e1;
  columns.col(1) = camera.R() * e2;
  columns.col(2) = camera.R() * origin + camera.t();
  Eigen::Matrix3d to_working = Eigen::Matrix3d::Identity();
  to_working(0, 0) = scale.sx;
  to_working(1, 1) = scale.sy;
  to_working(0, 2) = 0.5 * scale.sx - 0.5;
  to_working(1, 2) = 0.5 * scale.sy - 0.5;
  return to_working * camera.K() * columns;
}

/// Grey as float, its local mean and standard deviation over `window`.
struct Patches {
  cv::Mat grey, mean, deviation;
};
Patches patchesOf(const cv::Mat& grey_float, int window) {
  Patches p;
  p.grey = grey_float;
  cv::Mat square;
  cv::boxFilter(grey_float, p.mean, CV_32F, cv::Size(window, window));
  cv::boxFilter(grey_float.mul(grey_float), square, CV_32F, cv::Size(window, window));
  cv::sqrt(cv::max(square - p.mean.mul(p.mean), 0.0), p.deviation);
  return p;
}

cv::Mat greyOf(const cv::Mat& bgr) {
  cv::Mat grey, out;
  if (bgr.channels() == 3) {
    cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
  } else {
    grey = bgr;
  }
  grey.convertTo(out, CV_32F, 1.0 / 255.0);
  return out;
}

}  // namespace

namespace {

/// The frame of the plane {X : up . X = height}: origin and two axes in it.
struct PlaneFrame {
  Eigen::Vector3d origin, e1, e2;
};
PlaneFrame frameOf(const Eigen::Vector3d& up, double height) {
  const Eigen::Vector3d e1 = up.unitOrthogonal();
  return {height * up, e1, up.cross(e1)};
}

/// The NCC of each patch of `here` with `there` (another view, grey) carried by `h` (a pixel of
/// here -> its pixel there), -1 where it is not judged (no texture, outside `there`).
cv::Mat correlation(const Patches& here, const cv::Mat& there, const Eigen::Matrix3d& h) {
  // Texture to judge by, grey levels on [0, 1]: a shadow's texture is the floor's, darker.
  constexpr double kMinDeviation = 0.005;
  const cv::Size size = here.grey.size();
  cv::Mat map(3, 3, CV_64F);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) map.at<double>(r, c) = h(r, c);
  }
  cv::Mat warped, valid;
  cv::warpPerspective(there, warped, map, size, cv::INTER_LINEAR | cv::WARP_INVERSE_MAP,
                      cv::BORDER_CONSTANT, cv::Scalar(0));
  cv::warpPerspective(cv::Mat(there.size(), CV_8UC1, cv::Scalar(255)), valid, map, size,
                      cv::INTER_NEAREST | cv::WARP_INVERSE_MAP, cv::BORDER_CONSTANT, cv::Scalar(0));
  cv::erode(valid, valid, cv::Mat(), cv::Point(-1, -1), kPlaneWindow / 2);
  const Patches other = patchesOf(warped, kPlaneWindow);
  cv::Mat product, ncc;
  cv::boxFilter(here.grey.mul(warped), product, CV_32F, cv::Size(kPlaneWindow, kPlaneWindow));
  cv::divide(product - here.mean.mul(other.mean),
             cv::max(here.deviation.mul(other.deviation), 1e-6), ncc);
  const cv::Mat judged =
      (here.deviation > kMinDeviation) & (other.deviation > kMinDeviation) & valid;
  ncc.setTo(-1.0, judged == 0);
  return ncc;
}

/// The pixels of `here` whose patch agrees with `there` carried by `h`.
cv::Mat agreeing(const Patches& here, const cv::Mat& there, const Eigen::Matrix3d& h) {
  return correlation(here, there, h) > kPlaneNcc;
}

/// The `count` views nearest to view `v` in direction, among those above the plane.
std::vector<size_t> nearestAbove(const std::vector<PinholeCamera>& cameras, size_t v,
                                 const Eigen::Vector3d& up, double height, size_t count) {
  const Eigen::Vector3d axis = cameras[v].R().row(2).transpose();
  std::vector<std::pair<double, size_t>> nearest;
  for (size_t j = 0; j < cameras.size(); ++j) {
    if (j == v || !(up.dot(cameras[j].centre()) > height)) continue;
    nearest.emplace_back(-axis.dot(cameras[j].R().row(2).transpose()), j);
  }
  std::sort(nearest.begin(), nearest.end());
  std::vector<size_t> out;
  for (size_t i = 0; i < nearest.size() && i < count; ++i) out.push_back(nearest[i].second);
  return out;
}

/// The plane's homography from view v's pixels to view j's, or nullopt where it degenerates.
std::optional<Eigen::Matrix3d> homography(const PinholeCamera& v, const PinholeCamera& j,
                                          const PixelScale& scale, const PlaneFrame& plane) {
  const Eigen::Matrix3d from_v = planeToPixels(v, scale, plane.origin, plane.e1, plane.e2);
  if (!(std::abs(from_v.determinant()) > 1e-12)) return std::nullopt;
  return planeToPixels(j, scale, plane.origin, plane.e1, plane.e2) * from_v.inverse();
}

}  // namespace

cv::Mat planeGrey(const cv::Mat& bgr) { return greyOf(bgr); }

cv::Mat onPlane(const std::vector<cv::Mat>& greys, const std::vector<PinholeCamera>& cameras,
                const PixelScale& scale, size_t v, const Eigen::Vector3d& up, double height,
                double above, int neighbours) {
  cv::Mat result = cv::Mat::zeros(greys[v].size(), CV_8UC1);
  if (!(up.dot(cameras[v].centre()) > height)) return result;
  const PlaneFrame plane = frameOf(up, height), higher = frameOf(up, height + above);
  const Patches here = patchesOf(greys[v], kPlaneWindow);
  for (const size_t j : nearestAbove(cameras, v, up, height, static_cast<size_t>(neighbours))) {
    const auto h = homography(cameras[v], cameras[j], scale, plane);
    const auto h_higher = homography(cameras[v], cameras[j], scale, higher);
    if (!h || !h_higher) continue;
    const cv::Mat& there = greys[j];
    const cv::Mat ncc = correlation(here, there, *h);
    // A point of the object just above the plane (its base) matches nearly as well: it is on
    // the plane only where the plane matches better than one `above` higher.
    result |= (ncc > kPlaneNcc) & (ncc > correlation(here, there, *h_higher));
  }
  return result;
}

std::optional<double> supportHeight(const std::vector<cv::Mat>& images,
                                    const std::vector<cv::Mat>& objects,
                                    const std::vector<PinholeCamera>& cameras,
                                    const PixelScale& scale, const Eigen::Vector3d& up, double low,
                                    double high, double step, double* share_out) {
  // Half the working size is enough to find the plane; a few views spread over the set, each
  // against its nearest neighbour.
  const size_t n = images.size();
  const size_t probes = std::min<size_t>(6, n);
  std::vector<Patches> here(n);
  std::vector<cv::Mat> grey(n), around(n);
  const PixelScale half{scale.sx * 0.5, scale.sy * 0.5};
  for (size_t v = 0; v < n; ++v) {
    cv::Mat small;
    cv::resize(images[v], small, cv::Size(), 0.5, 0.5, cv::INTER_AREA);
    grey[v] = greyOf(small);
    // What the floor is judged on: the image outside the object's first mask, grown.
    cv::Mat object;
    cv::resize(objects[v], object, small.size(), 0, 0, cv::INTER_NEAREST);
    cv::dilate(object, object, cv::Mat(), cv::Point(-1, -1), 3);
    around[v] = object == 0;
  }
  const auto share = [&](double height) {
    const PlaneFrame plane = frameOf(up, height);
    double agreeing_pixels = 0.0, pixels = 0.0;
    for (size_t p = 0; p < probes; ++p) {
      const size_t v = p * n / probes;
      if (!(up.dot(cameras[v].centre()) > height)) continue;
      if (here[v].grey.empty()) here[v] = patchesOf(grey[v], kPlaneWindow);
      for (const size_t j : nearestAbove(cameras, v, up, height, 1)) {
        const auto h = homography(cameras[v], cameras[j], half, plane);
        if (!h) continue;
        agreeing_pixels += cv::countNonZero(agreeing(here[v], grey[j], *h) & around[v]);
        pixels += cv::countNonZero(around[v]);
      }
    }
    return pixels > 0.0 ? agreeing_pixels / pixels : 0.0;
  };
  // Coarse steps of four, then single steps around the best.
  double best = low, best_share = -1.0;
  for (double h = low; h <= high; h += 4.0 * step) {
    const double s = share(h);
    if (s > best_share) best_share = s, best = h;
  }
  const double centre = best;
  for (double h = centre - 3.0 * step; h <= centre + 3.0 * step; h += step) {
    const double s = share(h);
    if (s > best_share) best_share = s, best = h;
  }
  if (best_share < kMinPlaneShare) return std::nullopt;
  if (share_out != nullptr) *share_out = best_share;
  return best;
}

}  // namespace view_prior
}  // namespace sift_hull
