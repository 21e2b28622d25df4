#include "sift_hull/geometry/distortion.h"

#include <Eigen/LU>
#include <cmath>
#include <stdexcept>

namespace sift_hull {

namespace {

/// theta_d / r of the fisheye model and its derivative by r^2 (by series near the centre).
double fisheyeFactor(const LensDistortion& d, double r2, double* slope) {
  if (r2 < 1e-16) {
    if (slope != nullptr) *slope = d.k1 - 1.0 / 3.0;
    return 1.0;
  }
  const double r = std::sqrt(r2), theta = std::atan(r), t2 = theta * theta;
  const double poly = 1.0 + t2 * (d.k1 + t2 * (d.k2 + t2 * (d.k3 + t2 * d.k4)));
  const double theta_d = theta * poly;
  if (slope != nullptr) {
    const double dtheta_d =
        1.0 + t2 * (3.0 * d.k1 + t2 * (5.0 * d.k2 + t2 * (7.0 * d.k3 + t2 * 9.0 * d.k4)));
    const double ds_dr = (dtheta_d / (1.0 + r2) * r - theta_d) / r2;
    *slope = ds_dr / (2.0 * r);
  }
  return theta_d / r;
}

}  // namespace

double radialFactor(const LensDistortion& d, double r2, double* slope) {
  if (d.fisheye) return fisheyeFactor(d, r2, slope);
  const double numerator = 1.0 + r2 * (d.k1 + r2 * (d.k2 + r2 * d.k3));
  const double denominator = 1.0 + r2 * (d.k4 + r2 * (d.k5 + r2 * d.k6));
  if (slope != nullptr) {
    const double numerator_slope = d.k1 + r2 * (2.0 * d.k2 + 3.0 * r2 * d.k3);
    const double denominator_slope = d.k4 + r2 * (2.0 * d.k5 + 3.0 * r2 * d.k6);
    *slope = (numerator_slope * denominator - numerator * denominator_slope) /
             (denominator * denominator);
  }
  return numerator / denominator;
}

void validate(const LensDistortion& d) {
  const double coefficients[] = {d.k1, d.k2, d.p1, d.p2, d.k3, d.k4, d.k5, d.k6};
  for (double c : coefficients) {
    if (!std::isfinite(c))
      throw std::invalid_argument("a lens distortion coefficient is not finite");
  }
  if (d.fisheye && (d.p1 != 0.0 || d.p2 != 0.0 || d.k5 != 0.0 || d.k6 != 0.0)) {
    throw std::invalid_argument("a fisheye lens has k1..k4 only (p1, p2, k5, k6 must be 0)");
  }
}

Eigen::Vector2d distortNormalised(const LensDistortion& d, const Eigen::Vector2d& ideal) {
  const double x = ideal.x(), y = ideal.y();
  const double r2 = x * x + y * y;
  const double radial = radialFactor(d, r2);
  return {x * radial + 2.0 * d.p1 * x * y + d.p2 * (r2 + 2.0 * x * x),
          y * radial + d.p1 * (r2 + 2.0 * y * y) + 2.0 * d.p2 * x * y};
}

Eigen::Matrix2d distortionJacobian(const LensDistortion& d, const Eigen::Vector2d& ideal) {
  const double x = ideal.x(), y = ideal.y();
  const double r2 = x * x + y * y;
  double slope = 0.0;  // d radial / d r^2
  const double radial = radialFactor(d, r2, &slope);
  const double cross = 2.0 * x * y * slope + 2.0 * d.p1 * x + 2.0 * d.p2 * y;
  Eigen::Matrix2d J;
  J << radial + 2.0 * x * x * slope + 2.0 * d.p1 * y + 6.0 * d.p2 * x, cross, cross,
      radial + 2.0 * y * y * slope + 6.0 * d.p1 * y + 2.0 * d.p2 * x;
  return J;
}

std::optional<Eigen::Vector2d> undistortNormalised(const LensDistortion& d,
                                                   const Eigen::Vector2d& distorted) {
  if (!distorted.allFinite()) return std::nullopt;
  if (d.isZero()) return distorted;
  const double tolerance = 1e-12 * std::max(1.0, distorted.norm());
  Eigen::Vector2d ideal = distorted;
  for (int step = 0; step < 50; ++step) {
    const Eigen::Vector2d residual = distortNormalised(d, ideal) - distorted;
    if (!residual.allFinite()) return std::nullopt;
    const Eigen::Matrix2d J = distortionJacobian(d, ideal);
    const double det = J.determinant();
    // A root where the model folds over (det <= 0), or one turned through the centre (radial
    // factor <= 0, as r (1 + k1 r^2) has beyond its maximum), is not the point the lens imaged.
    if (residual.norm() <= tolerance) {
      const double radial = radialFactor(d, ideal.squaredNorm());
      return det > 0.0 && radial > 0.0 ? std::optional(ideal) : std::nullopt;
    }
    if (!(std::abs(det) > 1e-12)) return std::nullopt;
    ideal -= J.inverse() * residual;
  }
  return std::nullopt;
}

}  // namespace sift_hull
