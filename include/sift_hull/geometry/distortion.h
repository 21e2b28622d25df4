#pragma once

#include <Eigen/Core>
#include <optional>

namespace sift_hull {

/// Lens distortion in OpenCV's radial-tangential model and order (k1, k2, p1, p2, k3, k4, k5, k6;
/// ROS's plumb_bob is the first five, rational_polynomial all eight), applied to normalised camera
/// coordinates (x, y) = (X / Z, Y / Z):
///   r^2 = x^2 + y^2,  s = (1 + k1 r^2 + k2 r^4 + k3 r^6) / (1 + k4 r^2 + k5 r^4 + k6 r^6),
///   x_d = x s + 2 p1 x y + p2 (r^2 + 2 x^2),  y_d = y s + p1 (r^2 + 2 y^2) + 2 p2 x y.
/// All zero means an ideal pinhole.
///
/// With `fisheye`, OpenCV's fisheye model instead (ROS's equidistant; cv::fisheye), with k1..k4
/// its four coefficients and p1 = p2 = k5 = k6 = 0:
///   r = |(x, y)|,  theta = atan(r),  theta_d = theta (1 + k1 theta^2 + k2 theta^4 + k3 theta^6
///   + k4 theta^8),  (x_d, y_d) = (theta_d / r) (x, y).
/// A fisheye lens with all coefficients zero is the equidistant projection, not a pinhole.
struct LensDistortion {
  double k1 = 0.0;       ///< radial, r^2
  double k2 = 0.0;       ///< radial, r^4
  double p1 = 0.0;       ///< tangential
  double p2 = 0.0;       ///< tangential
  double k3 = 0.0;       ///< radial, r^6
  double k4 = 0.0;       ///< rational radial denominator, r^2
  double k5 = 0.0;       ///< rational radial denominator, r^4
  double k6 = 0.0;       ///< rational radial denominator, r^6
  bool fisheye = false;  ///< OpenCV's fisheye (equidistant) model, above

  /// True when every coefficient is exactly zero.
  bool isZero() const {
    return !fisheye && !rational() && k1 == 0.0 && k2 == 0.0 && p1 == 0.0 && p2 == 0.0 && k3 == 0.0;
  }
  /// True when a denominator coefficient (k4, k5, k6) is not zero: OpenCV's rational model.
  bool rational() const { return k4 != 0.0 || k5 != 0.0 || k6 != 0.0; }
};

/// The radial factor s at r^2 (the model above; theta_d / r for a fisheye lens); and, in `slope`
/// when given, ds / d(r^2).
double radialFactor(const LensDistortion& distortion, double r2, double* slope = nullptr);

/// Throws std::invalid_argument when a coefficient is NaN or infinite, or a fisheye lens has p1,
/// p2, k5 or k6 not zero.
void validate(const LensDistortion& distortion);

/// The distorted normalised point of an ideal one (the model above).
Eigen::Vector2d distortNormalised(const LensDistortion& distortion, const Eigen::Vector2d& ideal);

/// The Jacobian d(distorted) / d(ideal) at an ideal normalised point.
Eigen::Matrix2d distortionJacobian(const LensDistortion& distortion, const Eigen::Vector2d& ideal);

/// The ideal normalised point whose distortion is `distorted`, by Newton's method started at the
/// distorted point; empty when it does not converge to 1e-12 (relative) within 50 steps, the
/// Jacobian becomes singular, or the root found is not on the lens's branch of the model (the
/// Jacobian's determinant or the radial factor s not positive there: the point lies beyond where
/// the model folds over).
std::optional<Eigen::Vector2d> undistortNormalised(const LensDistortion& distortion,
                                                   const Eigen::Vector2d& distorted);

}  // namespace sift_hull
