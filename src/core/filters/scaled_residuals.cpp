#include "sift_hull/filters/scaled_residuals.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace sift_hull {

float octaveInterval_px(float keypoint_size_px) {
  const float interval = keypoint_size_px / (2.0f * kSiftBaseSigmaPx);
  return interval > 1.0f ? interval : 1.0f;  // also for NaN and negative sizes
}

double localScale(const TwoViewModel& model, double lx, double ly) {
  if (!model.homography) return 1.0;
  const double w = model.matrix(2, 0) * lx + model.matrix(2, 1) * ly + model.matrix(2, 2);
  const double scale = std::sqrt(std::abs(model.matrix.determinant()) / std::abs(w * w * w));
  return std::isfinite(scale) && scale > 0.0 ? scale : 1.0;
}

namespace {

/// The model's allowance at a left point: (max(1, 1 / s), max(1, s)), s its local scale there.
std::pair<double, double> modelIntervals(const TwoViewModel& model, double lx, double ly) {
  const double s = localScale(model, lx, ly);
  return {std::max(1.0, 1.0 / s), std::max(1.0, s)};
}

}  // namespace

PairScales modelScales(const TwoViewModel& model, const PointPairs& pairs) {
  PairScales scales;
  scales.left.assign(pairs.size(), 1.0f);
  scales.right.assign(pairs.size(), 1.0f);
  if (!model.homography) return scales;
  for (size_t i = 0; i < pairs.size(); ++i) {
    const auto [left, right] = modelIntervals(model, pairs.left_x[i], pairs.left_y[i]);
    scales.left[i] = static_cast<float>(left);
    scales.right[i] = static_cast<float>(right);
  }
  return scales;
}

std::pair<double, double> pairIntervals(const std::string& unit, const TwoViewModel& model,
                                        double lx, double ly, float left_size_px,
                                        float right_size_px) {
  if (unit == "model") return modelIntervals(model, lx, ly);
  if (unit == "keypoints")
    return {octaveInterval_px(left_size_px), octaveInterval_px(right_size_px)};
  return {1.0, 1.0};
}

double scaledModelResidual(const TwoViewModel& model, double lx, double ly, double rx, double ry,
                           double left_interval, double right_interval) {
  const Eigen::Matrix3d& M = model.matrix;
  const Eigen::Vector3d l(lx, ly, 1.0), r(rx, ry, 1.0);
  constexpr double kInfinity = std::numeric_limits<double>::infinity();
  if (!model.homography) {
    const Eigen::Vector3d line_r = M * l, line_l = M.transpose() * r;
    const double e = std::abs(r.dot(line_r));
    const double in_right = line_r.head<2>().norm() * right_interval;
    const double in_left = line_l.head<2>().norm() * left_interval;
    const double n = std::min(in_right, in_left);
    return n > 0.0 && std::isfinite(e / n) ? e / n : kInfinity;
  }
  const Eigen::Vector3d forward = M * l, backward = M.inverse() * r;
  const double f = (forward.hnormalized() - r.head<2>()).norm() / right_interval;
  const double b = (backward.hnormalized() - l.head<2>()).norm() / left_interval;
  return std::isfinite(f) && std::isfinite(b) ? std::max(f, b) : kInfinity;
}

void squaredScaledResiduals(const TwoViewModel& model, const PointPairs& pairs,
                            const PairScales& scales, std::vector<float>* out) {
  if (scales.left.size() != pairs.size() || scales.right.size() != pairs.size()) {
    throw std::invalid_argument("squaredScaledResiduals: one scale per pair in each image");
  }
  out->resize(pairs.size());
  float m[9], g[9];
  modelFloats(model, m, g);
  const float inf = std::numeric_limits<float>::infinity();
  for (size_t i = 0; i < pairs.size(); ++i) {
    const float lx = pairs.left_x[i], ly = pairs.left_y[i];
    const float rx = pairs.right_x[i], ry = pairs.right_y[i];
    const float sl2 = scales.left[i] * scales.left[i], sr2 = scales.right[i] * scales.right[i];
    float r2 = inf;
    if (model.homography) {
      const float w = m[6] * lx + m[7] * ly + m[8];
      const float u = (m[0] * lx + m[1] * ly + m[2]) / w - rx;
      const float v = (m[3] * lx + m[4] * ly + m[5]) / w - ry;
      const float wb = g[6] * rx + g[7] * ry + g[8];
      const float ub = (g[0] * rx + g[1] * ry + g[2]) / wb - lx;
      const float vb = (g[3] * rx + g[4] * ry + g[5]) / wb - ly;
      const float forward = (u * u + v * v) / sr2, backward = (ub * ub + vb * vb) / sl2;
      r2 = std::max(forward == forward ? forward : inf, backward == backward ? backward : inf);
    } else {
      const float a = m[0] * lx + m[1] * ly + m[2];
      const float b = m[3] * lx + m[4] * ly + m[5];
      const float c = m[6] * lx + m[7] * ly + m[8];
      const float d = m[0] * rx + m[3] * ry + m[6];
      const float e = m[1] * rx + m[4] * ry + m[7];
      const float error = rx * a + ry * b + c;
      r2 = error * error / std::min((a * a + b * b) * sr2, (d * d + e * e) * sl2);
      if (!(r2 == r2)) r2 = inf;  // NaN: undefined
    }
    (*out)[i] = r2;
  }
}

}  // namespace sift_hull
