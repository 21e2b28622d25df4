#pragma once

namespace sift_hull {

/// Lens distortion in OpenCV's radial-tangential model and order (k1, k2, p1, p2, k3), applied to
/// normalised camera coordinates. All zero means an ideal pinhole.
struct LensDistortion {
  double k1 = 0.0;  ///< radial, r^2
  double k2 = 0.0;  ///< radial, r^4
  double p1 = 0.0;  ///< tangential
  double p2 = 0.0;  ///< tangential
  double k3 = 0.0;  ///< radial, r^6

  /// True when every coefficient is exactly zero.
  bool isZero() const { return k1 == 0.0 && k2 == 0.0 && p1 == 0.0 && p2 == 0.0 && k3 == 0.0; }
};

}  // namespace sift_hull
