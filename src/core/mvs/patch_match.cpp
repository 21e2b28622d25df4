// Photo carving's slanted-plane PatchMatch (Bleyer, Rhemann and Rother, BMVC 2011; the scheme of
// COLMAP's and OpenMVS's dense stereo): each pixel of a view holds a plane, its depth and its
// normal in the view's camera, started from the plane sweep's fronto-parallel depth. Rounds in
// alternating scan order try the planes of the pixels before it (propagation) and two random
// perturbations of its own, of halving size, and keep what scores best. A plane is scored as the
// sweep scores a depth, the mean NCC of the best neighbours, through the homography the plane
// induces between the views: a surface that slants away from a view is matched as such, where a
// fronto-parallel patch would not be.
//
// Cost: rounds x pixels inside the silhouette x 4 planes x neighbours x (2 r + 1)^2 samples.

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <random>

#include "mvs/mvs_internal.h"

namespace sift_hull {
namespace detail {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
/// Planes seen more obliquely than this from the view's ray are not tried (their maps degenerate).
const float kMinCosine = std::cos(75.0f * static_cast<float>(M_PI) / 180.0f);

/// A pixel's plane in the reference camera: the points X with normal . X = normal . (depth ray),
/// the normal towards the camera.
struct Plane {
  Eigen::Vector3f normal{0.0f, 0.0f, -1.0f};
  float depth = kNaN;
};

/// Bilinear sample of a CV_32FC1 image at (x, y) inside [0, cols - 1] x [0, rows - 1].
inline float sample(const cv::Mat& image, float x, float y) {
  const int x0 = std::min(static_cast<int>(x), image.cols - 2);
  const int y0 = std::min(static_cast<int>(y), image.rows - 2);
  const float fx = x - x0, fy = y - y0;
  const float* top = image.ptr<float>(y0) + x0;
  const float* bottom = image.ptr<float>(y0 + 1) + x0;
  return (1.0f - fy) * ((1.0f - fx) * top[0] + fx * top[1]) +
         fy * ((1.0f - fx) * bottom[0] + fx * bottom[1]);
}

class PlaneScorer {
 public:
  PlaneScorer(const std::vector<ReducedView>& views, uint32_t view,
              const std::vector<uint32_t>& neighbours, const PhotoCarveConfig& config)
      : ref_(views[view]),
        radius_(config.photo_patch_radius_px),
        best_(std::min<int>(config.photo_best_neighbours, static_cast<int>(neighbours.size()))),
        min_var_(static_cast<float>(config.photo_min_patch_std * config.photo_min_patch_std)) {
    K_inv_ = ref_.camera.K().inverse().cast<float>();
    for (uint32_t n : neighbours) {
      const ReducedView& other = views[n];
      const Eigen::Matrix3d R_rel = other.camera.R() * ref_.camera.R().transpose();
      others_.push_back({&other.grey, other.camera.K().cast<float>(), R_rel.cast<float>(),
                         (other.camera.t() - R_rel * ref_.camera.t()).cast<float>()});
    }
    const cv::Size patch(2 * radius_ + 1, 2 * radius_ + 1);
    cv::boxFilter(ref_.grey, ref_mean_, CV_32F, patch, cv::Point(-1, -1), true,
                  cv::BORDER_REPLICATE);
    cv::boxFilter(ref_.grey.mul(ref_.grey), ref_var_, CV_32F, patch, cv::Point(-1, -1), true,
                  cv::BORDER_REPLICATE);
    ref_var_ -= ref_mean_.mul(ref_mean_);
  }

  Eigen::Vector3f ray(int u, int v) const { return K_inv_ * Eigen::Vector3f(u, v, 1.0f); }
  bool textured(int u, int v) const { return ref_var_.at<float>(v, u) > min_var_; }
  int best() const { return best_; }

  /// The score of the plane at pixel (u, v), NaN where fewer than best() neighbours see its patch.
  float score(int u, int v, const Plane& plane) const {
    const Eigen::Vector3f X = ray(u, v) * plane.depth;
    const float offset = plane.normal.dot(X);
    if (!(offset < 0.0f)) return kNaN;
    const float ref_mean = ref_mean_.at<float>(v, u);
    const float ref_std = std::sqrt(ref_var_.at<float>(v, u));
    const int side = 2 * radius_ + 1;
    const float count = static_cast<float>(side * side);
    float values[16];
    int used = 0;
    for (const Other& other : others_) {
      // X_other = R_rel X + t_rel, and on the plane n . X / offset = 1.
      const Eigen::Matrix3f H =
          other.K * (other.R_rel + other.t_rel * plane.normal.transpose() / offset) * K_inv_;
      const float x_max = other.grey->cols - 1.0f, y_max = other.grey->rows - 1.0f;
      float sum = 0.0f, sum_sq = 0.0f, cross = 0.0f;
      bool seen = true;
      for (int dv = -radius_; dv <= radius_ && seen; ++dv) {
        const float* ref_row = ref_.grey.ptr<float>(v + dv);
        Eigen::Vector3f x = H * Eigen::Vector3f(u - radius_, v + dv, 1.0f);
        const Eigen::Vector3f step = H.col(0);
        for (int du = -radius_; du <= radius_; ++du, x += step) {
          if (!(x.z() > 0.0f)) {
            seen = false;
            break;
          }
          const float px = x.x() / x.z(), py = x.y() / x.z();
          if (!(px >= 0.0f && py >= 0.0f && px <= x_max && py <= y_max)) {
            seen = false;
            break;
          }
          const float w = sample(*other.grey, px, py);
          sum += w, sum_sq += w * w, cross += w * ref_row[u + du];
        }
      }
      if (!seen) {
        values[used++] = kNaN;
        continue;
      }
      const float mean = sum / count;
      const float var = sum_sq / count - mean * mean;
      values[used++] =
          var > min_var_ ? (cross / count - ref_mean * mean) / (ref_std * std::sqrt(var)) : kNaN;
    }
    return bestMean(values, used, best_);
  }

 private:
  struct Other {
    const cv::Mat* grey;
    Eigen::Matrix3f K, R_rel;
    Eigen::Vector3f t_rel;
  };
  const ReducedView& ref_;
  const int radius_, best_;
  const float min_var_;
  Eigen::Matrix3f K_inv_;
  std::vector<Other> others_;
  cv::Mat ref_mean_, ref_var_;
};

}  // namespace

void patchMatchDepth(const std::vector<ReducedView>& views, uint32_t view,
                     const std::vector<uint32_t>& neighbours, const DepthRange& range,
                     const PhotoCarveConfig& config, double voxel_m, cv::Mat* depth_m,
                     cv::Mat* ncc) {
  const int rounds = config.photo_patch_match_rounds;
  if (rounds < 1 || neighbours.empty() || neighbours.size() > 16) return;
  const PlaneScorer scorer(views, view, neighbours, config);
  if (scorer.best() < 1) return;
  const ReducedView& ref = views[view];
  const int rows = ref.grey.rows, cols = ref.grey.cols;
  const float margin_m = static_cast<float>(2.0 * voxel_m);
  std::mt19937 random(0x5eed0000u + view);  // per view: the same planes on any number of threads
  std::uniform_real_distribution<float> unit(0.0f, 1.0f), signed_unit(-1.0f, 1.0f);
  std::vector<Plane> planes(static_cast<size_t>(rows) * cols);
  std::vector<float> scores(planes.size(), kNaN);
  std::vector<uint8_t> active(planes.size(), 0);
  const auto inverseSpan = [&](int u, int v, float* inv_near, float* inv_far) {
    *inv_near = 1.0f / std::max(range.near_m.at<float>(v, u) - margin_m, 1e-6f);
    *inv_far = 1.0f / (range.far_m.at<float>(v, u) + margin_m);
  };
  const auto inRange = [&](int u, int v, float depth) {
    return depth >= range.near_m.at<float>(v, u) - margin_m &&
           depth <= range.far_m.at<float>(v, u) + margin_m;
  };
  for (int v = 0; v < rows; ++v) {
    for (int u = 0; u < cols; ++u) {
      if (!ref.inside.at<uint8_t>(v, u) || std::isnan(range.near_m.at<float>(v, u)) ||
          !scorer.textured(u, v)) {
        continue;
      }
      const size_t at = static_cast<size_t>(v) * cols + u;
      active[at] = 1;
      Plane& plane = planes[at];
      plane.depth = depth_m->at<float>(v, u);
      if (std::isnan(plane.depth)) {  // no depth from the sweep: a random one within range
        float inv_near, inv_far;
        inverseSpan(u, v, &inv_near, &inv_far);
        plane.depth = 1.0f / (inv_far + unit(random) * (inv_near - inv_far));
      }
      scores[at] = scorer.score(u, v, plane);
    }
  }
  const auto tryPlane = [&](int u, int v, size_t at, const Plane& plane) {
    if (!inRange(u, v, plane.depth)) return;
    const Eigen::Vector3f ray = scorer.ray(u, v);
    if (-plane.normal.dot(ray.normalized()) < kMinCosine) return;
    const float s = scorer.score(u, v, plane);
    if (s > scores[at] || (std::isnan(scores[at]) && !std::isnan(s))) {
      planes[at] = plane, scores[at] = s;
    }
  };
  for (int round = 0; round < rounds; ++round) {
    const bool forward = round % 2 == 0;
    const int step = forward ? 1 : -1;
    const float size = std::ldexp(1.0f, -(round + 1));  // the perturbations halve every round
    for (int i = 0; i < rows; ++i) {
      const int v = forward ? i : rows - 1 - i;
      for (int j = 0; j < cols; ++j) {
        const int u = forward ? j : cols - 1 - j;
        const size_t at = static_cast<size_t>(v) * cols + u;
        if (!active[at]) continue;
        const Eigen::Vector3f ray = scorer.ray(u, v);
        // Propagation: the planes of the pixels before this one in the scan, at this pixel.
        for (const auto& [du, dv] : {std::pair<int, int>{-step, 0}, {0, -step}}) {
          const int nu = u + du, nv = v + dv;
          if (nu < 0 || nv < 0 || nu >= cols || nv >= rows) continue;
          const size_t from = static_cast<size_t>(nv) * cols + nu;
          if (!active[from] || std::isnan(scores[from])) continue;
          const Plane& source = planes[from];
          const float offset = source.normal.dot(scorer.ray(nu, nv) * source.depth);
          const float denominator = source.normal.dot(ray);
          if (!(std::abs(denominator) > 1e-9f)) continue;
          Plane moved = source;
          moved.depth = offset / denominator;
          tryPlane(u, v, at, moved);
        }
        // Refinement: this pixel's plane with its depth (in inverse depth) or its normal moved.
        float inv_near, inv_far;
        inverseSpan(u, v, &inv_near, &inv_far);
        Plane deeper = planes[at];
        const float inv = 1.0f / deeper.depth + signed_unit(random) * size * (inv_near - inv_far);
        deeper.depth = 1.0f / std::clamp(inv, inv_far, inv_near);
        tryPlane(u, v, at, deeper);
        Plane turned = planes[at];
        turned.normal +=
            size * Eigen::Vector3f(signed_unit(random), signed_unit(random), signed_unit(random));
        if (turned.normal.squaredNorm() > 1e-12f) {
          turned.normal.normalize();
          tryPlane(u, v, at, turned);
        }
      }
    }
  }
  for (int v = 0; v < rows; ++v) {
    for (int u = 0; u < cols; ++u) {
      const size_t at = static_cast<size_t>(v) * cols + u;
      if (!active[at]) continue;
      depth_m->at<float>(v, u) = std::isnan(scores[at]) ? kNaN : planes[at].depth;
      ncc->at<float>(v, u) = scores[at];
    }
  }
}

}  // namespace detail
}  // namespace sift_hull
