// SurfacePoints messages: a pair's triangulated matches and its cameras, to and from the core.

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "lib/conversions.h"

namespace sift_hull {
namespace ros_conversions {
namespace {

template <size_t N>
bool finite(const boost::array<double, N>& values) {
  for (const double v : values) {
    if (!std::isfinite(v)) return false;
  }
  return true;
}

void putCamera(const PinholeCamera& camera, boost::array<double, 9>* K, boost::array<double, 9>* R,
               boost::array<double, 3>* t) {
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      (*K)[3 * r + c] = camera.K()(r, c);
      (*R)[3 * r + c] = camera.R()(r, c);
    }
    (*t)[r] = camera.t()(r);
  }
}

/// The camera in the message's frame, then in the world: x ~ K (R T_F_W X_W + t).
PinholeCamera cameraOf(const boost::array<double, 9>& K, const boost::array<double, 9>& R,
                       const boost::array<double, 3>& t, const Eigen::Isometry3d& T_W_F) {
  const Eigen::Matrix3d K_m =
      Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(K.data());
  const Eigen::Matrix3d R_m =
      Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(R.data());
  const Eigen::Vector3d t_v(t[0], t[1], t[2]);
  const Eigen::Isometry3d T_F_W = T_W_F.inverse();
  return PinholeCamera(K_m, R_m * T_F_W.linear(), R_m * T_F_W.translation() + t_v);
}

}  // namespace

sift_hull::SurfacePoints surfacePointsMessage(const std_msgs::Header& header,
                                              const PinholeCamera& left, const PinholeCamera& right,
                                              const std::vector<SurfacePoint>& points) {
  sift_hull::SurfacePoints message;
  message.header = header;
  putCamera(left, &message.left_K, &message.left_R, &message.left_t);
  putCamera(right, &message.right_K, &message.right_R, &message.right_t);
  for (const SurfacePoint& point : points) {
    geometry_msgs::Point p;
    p.x = point.X_W.x(), p.y = point.X_W.y(), p.z = point.X_W.z();
    message.points.push_back(p);
    message.reprojection_px.push_back(static_cast<float>(point.reprojection_px));
  }
  return message;
}

bool surfacePointsFromMessage(const sift_hull::SurfacePoints& message,
                              const Eigen::Isometry3d& T_W_F, PinholeCamera* left,
                              PinholeCamera* right, std::vector<SurfacePoint>* points,
                              std::string* why_not, size_t max_points) {
  if (message.points.size() != message.reprojection_px.size()) {
    *why_not = std::to_string(message.points.size()) + " points but " +
               std::to_string(message.reprojection_px.size()) + " reprojection errors";
    return false;
  }
  if (!finite(message.left_K) || !finite(message.left_R) || !finite(message.left_t) ||
      !finite(message.right_K) || !finite(message.right_R) || !finite(message.right_t)) {
    *why_not = "a camera holds a value that is not finite";
    return false;
  }
  try {
    *left = cameraOf(message.left_K, message.left_R, message.left_t, T_W_F);
    *right = cameraOf(message.right_K, message.right_R, message.right_t, T_W_F);
  } catch (const std::invalid_argument& e) {
    *why_not = std::string("a camera is refused: ") + e.what();
    return false;
  }
  const size_t n = message.points.size();
  for (size_t i = 0; i < n; ++i) {
    const geometry_msgs::Point& p = message.points[i];
    const double error = message.reprojection_px[i];
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z) || !(error >= 0.0) ||
        !std::isfinite(error)) {
      *why_not = "point " + std::to_string(i) +
                 " or its reprojection error is not a finite "
                 "number (>= 0 for the error)";
      return false;
    }
  }
  const size_t keep = std::min(n, std::max<size_t>(max_points, 1));
  points->clear();
  points->reserve(keep);
  for (size_t k = 0; k < keep; ++k) {
    const size_t i = keep == n ? k : static_cast<size_t>(static_cast<double>(k) * n / keep);
    const geometry_msgs::Point& p = message.points[i];
    SurfacePoint point;
    point.X_W = T_W_F * Eigen::Vector3d(p.x, p.y, p.z);
    point.reprojection_px = message.reprojection_px[i];
    point.depth_sigma_m = depthSigma(*left, *right, point.X_W, point.reprojection_px);
    point.views = {0, 1};
    points->push_back(point);
  }
  return true;
}

}  // namespace ros_conversions
}  // namespace sift_hull
