#include "sift_hull/geometry/camera.h"

#include <Eigen/LU>
#include <Eigen/QR>
#include <Eigen/SVD>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace sift_hull {
namespace {

// Middlebury rotations are given to about 1e-6; looser than that still catches a wrong matrix.
constexpr double kRotationTolerance = 1e-4;

void checkIntrinsics(const Eigen::Matrix3d& K) {
  if (!K.allFinite()) throw std::invalid_argument("K has a non-finite entry");
  if (K(2, 2) == 0.0) throw std::invalid_argument("K(3,3) is zero");
  const double scale = K.cwiseAbs().maxCoeff();
  const double lower = std::abs(K(1, 0)) + std::abs(K(2, 0)) + std::abs(K(2, 1));
  if (lower > 1e-9 * scale) throw std::invalid_argument("K is not upper triangular");
  if (std::abs(K.determinant()) <= 1e-12 * scale * scale * scale) {
    throw std::invalid_argument("K is singular");
  }
  if (K(0, 0) / K(2, 2) <= 0.0 || K(1, 1) / K(2, 2) <= 0.0) {
    throw std::invalid_argument("K has a non-positive focal length");
  }
}

void checkRotation(const Eigen::Matrix3d& R) {
  if (!R.allFinite()) throw std::invalid_argument("R has a non-finite entry");
  const double orthogonality =
      (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (orthogonality > kRotationTolerance) {
    throw std::invalid_argument(
        "R is not orthonormal (max |R^T R - I| = " + std::to_string(orthogonality) + ")");
  }
  if (R.determinant() < 0.0) throw std::invalid_argument("R has det -1 (a reflection)");
}

}  // namespace

PinholeCamera::PinholeCamera(const Eigen::Matrix3d& K, const Eigen::Matrix3d& R,
                             const Eigen::Vector3d& t)
    : R_(R), t_(t) {
  checkIntrinsics(K);
  checkRotation(R);
  if (!t.allFinite()) throw std::invalid_argument("t has a non-finite entry");
  K_ = K / K(2, 2);
  K_inv_ = K_.inverse();
}

PinholeCamera PinholeCamera::fromCentre(const Eigen::Matrix3d& K, const Eigen::Matrix3d& R,
                                        const Eigen::Vector3d& centre) {
  return PinholeCamera(K, R, -R * centre);
}

PinholeCamera PinholeCamera::fromProjection(const Matrix34d& P) {
  if (!P.allFinite()) throw std::invalid_argument("P has a non-finite entry");
  Eigen::Matrix3d M = P.leftCols<3>();
  Eigen::Vector3d p4 = P.col(3);
  const double det = M.determinant();
  if (std::abs(det) <= 1e-12 * std::pow(M.cwiseAbs().maxCoeff(), 3)) {
    throw std::invalid_argument("the left 3x3 block of P is singular");
  }
  if (det < 0.0) {  // P is defined up to scale; a negative scale would give det R = -1.
    M = -M;
    p4 = -p4;
  }
  // RQ decomposition M = K R through the QR decomposition of the row-reversed, transposed M.
  Eigen::Matrix3d reverse = Eigen::Matrix3d::Zero();
  reverse(0, 2) = reverse(1, 1) = reverse(2, 0) = 1.0;
  Eigen::HouseholderQR<Eigen::Matrix3d> qr((reverse * M).transpose());
  const Eigen::Matrix3d q = qr.householderQ();
  const Eigen::Matrix3d r = qr.matrixQR().triangularView<Eigen::Upper>();
  Eigen::Matrix3d K = reverse * r.transpose() * reverse;
  Eigen::Matrix3d R = reverse * q.transpose();
  const Eigen::Vector3d signs = K.diagonal().array().sign();
  K = K * signs.asDiagonal();
  R = signs.asDiagonal() * R;
  const Eigen::Vector3d t = K.inverse() * p4;
  return PinholeCamera(K, R, t);
}

PinholeCamera PinholeCamera::negated() const {
  PinholeCamera camera = *this;
  camera.R_ = -R_;
  camera.t_ = -t_;
  return camera;
}

PinholeCamera PinholeCamera::reduced(int factor) const {
  if (factor < 1) throw std::invalid_argument("PinholeCamera::reduced: factor below 1");
  if (factor == 1) return *this;
  const double s = 1.0 / factor, shift = 0.5 * (s - 1.0);
  Eigen::Matrix3d S;
  S << s, 0.0, shift, 0.0, s, shift, 0.0, 0.0, 1.0;
  PinholeCamera camera = *this;
  camera.K_ = S * K_;
  camera.K_inv_ = camera.K_.inverse();
  return camera;
}

Matrix34d PinholeCamera::projectionMatrix() const {
  Matrix34d Rt;
  Rt << R_, t_;
  return K_ * Rt;
}

PinholeCamera PinholeCamera::withDistortion(const LensDistortion& distortion) const {
  validate(distortion);
  PinholeCamera camera = *this;
  camera.distortion_ = distortion;
  return camera;
}

Eigen::Vector2d PinholeCamera::projectIdeal(const Eigen::Vector3d& X_W) const {
  return (K_ * toCamera(X_W)).hnormalized();
}

Eigen::Vector2d PinholeCamera::project(const Eigen::Vector3d& X_W) const {
  if (!distorted()) return projectIdeal(X_W);
  const Eigen::Vector2d normalised = toCamera(X_W).hnormalized();
  return (K_ * distortNormalised(distortion_, normalised).homogeneous()).hnormalized();
}

std::optional<Eigen::Vector2d> PinholeCamera::undistortPixel(const Eigen::Vector2d& raw_px) const {
  if (!distorted()) return raw_px;
  const Eigen::Vector2d distorted = (K_inv_ * raw_px.homogeneous()).hnormalized();
  const std::optional<Eigen::Vector2d> ideal = undistortNormalised(distortion_, distorted);
  if (!ideal) return std::nullopt;
  return (K_ * ideal->homogeneous()).hnormalized();
}

Eigen::Vector2d PinholeCamera::distortPixel(const Eigen::Vector2d& ideal_px) const {
  if (!distorted()) return ideal_px;
  const Eigen::Vector2d ideal = (K_inv_ * ideal_px.homogeneous()).hnormalized();
  return (K_ * distortNormalised(distortion_, ideal).homogeneous()).hnormalized();
}

Eigen::Vector3d PinholeCamera::rayDirection(const Eigen::Vector2d& pixel) const {
  const std::optional<Eigen::Vector2d> ideal = undistortPixel(pixel);
  if (!ideal) return Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  return (R_.transpose() * (K_inv_ * ideal->homogeneous())).normalized();
}

Eigen::Vector3d PinholeCamera::backProject(const Eigen::Vector2d& pixel, double depth) const {
  const std::optional<Eigen::Vector2d> ideal = undistortPixel(pixel);
  if (!ideal) return Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  const Eigen::Vector3d X_C = depth * (K_inv_ * ideal->homogeneous());
  return R_.transpose() * (X_C - t_);
}

std::pair<Eigen::Vector2d, Eigen::Vector2d> PinholeCamera::undistortedBounds(
    const Eigen::Vector2d& raw_min_px, const Eigen::Vector2d& raw_max_px) const {
  if (!distorted()) return {raw_min_px, raw_max_px};
  Eigen::Vector2d low = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector2d high = -low;
  const auto include = [&](const Eigen::Vector2d& raw) {
    const std::optional<Eigen::Vector2d> ideal = undistortPixel(raw);
    if (!ideal) {
      throw std::invalid_argument("the lens distortion cannot be inverted at raw pixel (" +
                                  std::to_string(raw.x()) + ", " + std::to_string(raw.y()) + ")");
    }
    low = low.cwiseMin(*ideal);
    high = high.cwiseMax(*ideal);
  };
  const Eigen::Vector2d extent = raw_max_px - raw_min_px;
  const int steps = static_cast<int>(std::ceil(std::max(extent.x(), extent.y()))) + 1;
  for (int i = 0; i <= steps; ++i) {
    const double f = static_cast<double>(i) / steps;
    const double u = raw_min_px.x() + f * extent.x(), v = raw_min_px.y() + f * extent.y();
    include({u, raw_min_px.y()});
    include({u, raw_max_px.y()});
    include({raw_min_px.x(), v});
    include({raw_max_px.x(), v});
  }
  return {low, high};
}

bool PinholeCamera::distortionInvertibleOver(const Eigen::Vector2d& raw_min_px,
                                             const Eigen::Vector2d& raw_max_px) const {
  if (!distorted()) return true;
  const Eigen::Vector2d extent = raw_max_px - raw_min_px;
  const int steps = std::max(2, static_cast<int>(std::ceil(extent.maxCoeff() / 64.0)));
  for (int i = 0; i <= steps; ++i) {
    for (int j = 0; j <= steps; ++j) {
      const Eigen::Vector2d raw =
          raw_min_px + Eigen::Vector2d(extent.x() * i, extent.y() * j) / steps;
      if (!undistortPixel(raw)) return false;
    }
  }
  return true;
}

void requireUnfoldedDistortion(const std::string& name, const PinholeCamera& camera, int width_px,
                               int height_px, int padding_px) {
  if (!camera.distorted()) return;
  // The image's pixels reach half a pixel past the first and last pixel centres.
  const double pad = padding_px + 0.5;
  const Eigen::Vector2d low(-pad, -pad);
  const Eigen::Vector2d high(width_px - 1 + pad, height_px - 1 + pad);
  if (!camera.distortionInvertibleOver(low, high)) {
    throw std::invalid_argument("view '" + name + "': its lens distortion folds over within its " +
                                std::to_string(width_px) + "x" + std::to_string(height_px) +
                                " image (no one-to-one undistortion): check the coefficients and "
                                "the image size");
  }
}

Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

Eigen::Matrix3d fundamentalMatrix(const PinholeCamera& a, const PinholeCamera& b) {
  const Eigen::Matrix3d R_ba = b.R() * a.R().transpose();
  const Eigen::Vector3d t_ba = b.t() - R_ba * a.t();
  return b.K().inverse().transpose() * skew(t_ba) * R_ba * a.K().inverse();
}

EpipolarDistances epipolarDistances(const Eigen::Matrix3d& F, const Eigen::Vector2d& x_a,
                                    const Eigen::Vector2d& x_b) {
  const Eigen::Vector3d line_in_b = F * x_a.homogeneous();
  const Eigen::Vector3d line_in_a = F.transpose() * x_b.homogeneous();
  const double residual = std::abs(x_b.homogeneous().dot(line_in_b));
  const auto distance = [residual](const Eigen::Vector3d& line) {
    const double norm = line.head<2>().norm();
    return norm > 0.0 ? residual / norm : std::numeric_limits<double>::infinity();
  };
  return {distance(line_in_a), distance(line_in_b)};
}

std::optional<Eigen::Vector3d> triangulate(const PinholeCamera& a, const PinholeCamera& b,
                                           const Eigen::Vector2d& x_a, const Eigen::Vector2d& x_b) {
  const Matrix34d P_a = a.projectionMatrix(), P_b = b.projectionMatrix();
  Eigen::Matrix4d A;
  A.row(0) = x_a.x() * P_a.row(2) - P_a.row(0);
  A.row(1) = x_a.y() * P_a.row(2) - P_a.row(1);
  A.row(2) = x_b.x() * P_b.row(2) - P_b.row(0);
  A.row(3) = x_b.y() * P_b.row(2) - P_b.row(1);
  const Eigen::Vector4d X =
      Eigen::JacobiSVD<Eigen::Matrix4d>(A, Eigen::ComputeFullV).matrixV().col(3);
  if (std::abs(X.w()) < 1e-12) return std::nullopt;
  const Eigen::Vector3d X_W = X.head<3>() / X.w();
  if (!(a.depth(X_W) > 0.0 && b.depth(X_W) > 0.0)) return std::nullopt;
  return X_W;
}

}  // namespace sift_hull
