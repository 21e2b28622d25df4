#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <optional>
#include <string>
#include <utility>

#include "sift_hull/geometry/distortion.h"

namespace sift_hull {

using Matrix34d = Eigen::Matrix<double, 3, 4>;

/// A pinhole camera in the Middlebury convention x ~ K [R | t] X: R and t take world points into
/// the camera frame (z forward, x right, y down), K maps the camera frame to pixels. Pixel (u, v)
/// is the centre of the pixel in column u and row v, origin at the top-left pixel's centre.
///
/// Mirrored worlds. A 3x4 projection matrix is defined up to scale, sign included, and a world
/// frame may be left-handed (one axis of a right-handed frame negated): then the left 3x3 block of
/// the P that sees the scene in front has det < 0, and no rotation with det +1 gives the same
/// projection. Such a camera is kept as it is, "improper", with an orthogonal R of det -1
/// (negated()): projection, depth, centre, optical axis and back-projection hold for any
/// orthogonal R, and the hull is carved on the world points as given, so the LP box, the octree,
/// the OctoMap and the mesh (its winding and volume come from the occupancy in world coordinates,
/// not from the cameras) are those of the mirrored scene, correct as they are. Mirroring the world
/// back on reading instead would have to mirror every output, and flip the mesh's winding, again.
/// Which sign of P is the right one is a property of a set of views, not of one matrix: see
/// orientCameras (geometry/camera_set.h). An improper R has no quaternion: a TF pose of such a
/// camera is not a rigid motion. The constructor takes rotations only (det +1).
///
/// Lens distortion (as image_geometry's PinholeCameraModel and OpenCV hold it): pixels of the
/// image as taken ("raw") are K applied to the distorted normalised point, distortNormalised(X/Z,
/// Y/Z); "ideal" pixels are those of the undistorted pinhole K [R | t]. project, rayDirection and
/// backProject work on raw pixels; projectionMatrix, fundamentalMatrix and triangulate on ideal
/// ones (undistortPixel converts). Without distortion the two coincide.
class PinholeCamera {
 public:
  PinholeCamera() = default;
  /// Throws std::invalid_argument when K is singular or not upper triangular with K(2,2) != 0, or
  /// when R is not a rotation (orthonormal with det +1, to 1e-4).
  PinholeCamera(const Eigen::Matrix3d& K, const Eigen::Matrix3d& R, const Eigen::Vector3d& t);

  /// The paper's form u ~ K [R | -R c] U, with c the camera centre in world coordinates.
  static PinholeCamera fromCentre(const Eigen::Matrix3d& K, const Eigen::Matrix3d& R,
                                  const Eigen::Vector3d& centre);
  /// Decomposes P = K [R | t] (any non-zero scale) by RQ decomposition into a K with positive focal
  /// lengths and K(2,2) = 1, and a rotation with det R = +1 (P's sign chosen for that; the camera
  /// set's orientation, orientCameras, may negate it afterwards). Throws std::invalid_argument when
  /// the left 3x3 block of P is singular.
  static PinholeCamera fromProjection(const Matrix34d& P);

  /// The same projection with P's sign flipped: R and t negated, K kept. Every depth changes sign;
  /// pixels and the centre stay. A proper camera (det R = +1) becomes improper and back.
  PinholeCamera negated() const;
  /// True when det R = -1: the camera lives in a mirrored (left-handed) world frame.
  bool improper() const { return R_.determinant() < 0.0; }
  /// The same camera for its image reduced `factor` times on each side, as libjpeg's scaled
  /// decoding and cv::resize with INTER_AREA reduce it: reduced pixel u' covers full pixels
  /// factor * u' .. factor * u' + factor - 1, so u' = (u + 0.5) / factor - 0.5. R, t and the
  /// distortion are kept. Throws std::invalid_argument for a factor below 1.
  PinholeCamera reduced(int factor) const;
  /// The same camera with this lens distortion. Throws std::invalid_argument for a non-finite
  /// coefficient.
  PinholeCamera withDistortion(const LensDistortion& distortion) const;
  const LensDistortion& distortion() const { return distortion_; }
  bool distorted() const { return !distortion_.isZero(); }

  const Eigen::Matrix3d& K() const { return K_; }
  const Eigen::Matrix3d& R() const { return R_; }
  const Eigen::Vector3d& t() const { return t_; }
  Eigen::Vector3d centre() const { return -R_.transpose() * t_; }
  /// Unit vector of the optical axis (camera z) in world coordinates.
  Eigen::Vector3d opticalAxis() const { return R_.row(2).transpose(); }
  Matrix34d projectionMatrix() const;

  /// World point into the camera frame.
  Eigen::Vector3d toCamera(const Eigen::Vector3d& X_W) const { return R_ * X_W + t_; }
  /// Depth of a world point along the optical axis (positive in front of the camera).
  double depth(const Eigen::Vector3d& X_W) const { return toCamera(X_W).z(); }
  /// Raw pixel of a world point (with the lens distortion); meaningful only where depth > 0.
  Eigen::Vector2d project(const Eigen::Vector3d& X_W) const;
  /// Ideal pixel of a world point: K [R | t] X, no distortion.
  Eigen::Vector2d projectIdeal(const Eigen::Vector3d& X_W) const;
  /// The ideal pixel of a raw one; empty where the distortion cannot be inverted (see
  /// undistortNormalised). The raw pixel itself without distortion.
  std::optional<Eigen::Vector2d> undistortPixel(const Eigen::Vector2d& raw_px) const;
  /// The raw pixel of an ideal one.
  Eigen::Vector2d distortPixel(const Eigen::Vector2d& ideal_px) const;
  /// Unit direction, in world coordinates, of the ray from the centre through raw pixel (u, v);
  /// NaN where undistortPixel is empty.
  Eigen::Vector3d rayDirection(const Eigen::Vector2d& pixel) const;
  /// The world point seen at a raw pixel at the given depth along the optical axis; NaN where
  /// undistortPixel is empty.
  Eigen::Vector3d backProject(const Eigen::Vector2d& pixel, double depth) const;
  /// The smallest box of ideal pixels, [u_min, u_max] x [v_min, v_max] in (min, max), that holds
  /// the undistorted image of the raw rectangle [u0, u1] x [v0, v1] (its border sampled at least
  /// every pixel, the interior mapped inside as long as the distortion does not fold over). Throws
  /// std::invalid_argument when a border point cannot be undistorted.
  std::pair<Eigen::Vector2d, Eigen::Vector2d> undistortedBounds(
      const Eigen::Vector2d& raw_min_px, const Eigen::Vector2d& raw_max_px) const;
  /// Whether the distortion is one-to-one over raw rectangle [u0, u1] x [v0, v1]: every raw point
  /// of a grid over it (at most 64 px apart, border included) undistorts, with a Jacobian of
  /// positive determinant. True without distortion.
  bool distortionInvertibleOver(const Eigen::Vector2d& raw_min_px,
                                const Eigen::Vector2d& raw_max_px) const;

 private:
  Eigen::Matrix3d K_ = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d R_ = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t_ = Eigen::Vector3d::Zero();
  Eigen::Matrix3d K_inv_ = Eigen::Matrix3d::Identity();
  LensDistortion distortion_;
};

/// Throws std::invalid_argument "view 'NAME': its lens distortion folds over within its WxH image
/// ..." when the camera's distortion is not one-to-one (distortionInvertibleOver) over its
/// width_px x height_px image widened by `padding_px` on each side. The hull's views (with their
/// distance maps' padding), the match command and the matcher node check their cameras with it.
void requireUnfoldedDistortion(const std::string& name, const PinholeCamera& camera, int width_px,
                               int height_px, int padding_px = 0);

/// Cross-product matrix [v]x, so that [v]x w = v x w.
Eigen::Matrix3d skew(const Eigen::Vector3d& v);

/// Fundamental matrix F with x_b^T F x_a = 0 for every scene point seen at x_a in view a and x_b in
/// view b (ideal pixels, homogeneous: undistortPixel first for distorted cameras). The paper's eq.
/// 10, F = A_r^-T [t]x R A_l^-1, with the relative pose R = R_b R_a^T and t = t_b - R t_a taking
/// camera-a coordinates into camera b.
Eigen::Matrix3d fundamentalMatrix(const PinholeCamera& a, const PinholeCamera& b);

/// The world point seen at ideal pixel x_a in view a and at x_b in view b, by linear triangulation
/// (DLT, the smallest singular vector); empty when it is at infinity or not in front of both
/// cameras.
std::optional<Eigen::Vector3d> triangulate(const PinholeCamera& a, const PinholeCamera& b,
                                           const Eigen::Vector2d& x_a, const Eigen::Vector2d& x_b);

/// Distances in pixels of each point of a match to the epipolar line of the other.
struct EpipolarDistances {
  double in_a_px;  ///< distance of x_a to the line F^T x_b in image a
  double in_b_px;  ///< distance of x_b to the line F x_a in image b
  double max() const { return in_a_px > in_b_px ? in_a_px : in_b_px; }
};

/// Symmetric point-to-epipolar-line distance of a match (x_a, x_b) under F (x_b^T F x_a = 0).
/// A degenerate line (a point at an epipole) gives infinite distance.
EpipolarDistances epipolarDistances(const Eigen::Matrix3d& F, const Eigen::Vector2d& x_a,
                                    const Eigen::Vector2d& x_b);

}  // namespace sift_hull
