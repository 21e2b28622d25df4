// camera_info to PinholeCamera, read through image_geometry::PinholeCameraModel: which of K, D, R
// and P describe the image is decided here (see cameraInfoGeometry in conversions.h).

#include <image_geometry/pinhole_camera_model.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <opencv2/core/eigen.hpp>
#include <sstream>
#include <stdexcept>

#include "lib/conversions.h"
#include "sift_hull/limits.h"

namespace sift_hull {
namespace ros_conversions {
namespace {

bool intrinsicsValid(Eigen::Matrix3d* K, const std::string& name, std::string* why_not) {
  if (!K->allFinite()) {
    *why_not = "camera_info " + name + " holds a value that is not finite";
    return false;
  }
  if ((*K)(2, 2) == 0.0) {
    *why_not = K->isZero() ? "camera_info " + name + " is all zero (an uncalibrated camera?)"
                           : "camera_info " + name + (name == "P" ? "[10]" : "[8]") + " is 0";
    return false;
  }
  *K /= (*K)(2, 2);
  if ((*K)(1, 0) != 0.0 || (*K)(2, 0) != 0.0 || (*K)(2, 1) != 0.0 || !((*K)(0, 0) > 0.0) ||
      !((*K)(1, 1) > 0.0)) {
    *why_not = "camera_info " + name + " is not upper triangular with positive focal lengths";
    return false;
  }
  return true;
}

/// D as LensDistortion: plumb_bob (or an empty model) with 5 coefficients, rational_polynomial
/// with 8, equidistant (OpenCV's fisheye) with 4; all zero (or none) is no distortion whatever the
/// model, as image_geometry has it.
bool distortionFromCoefficients(const std::string& model, const std::vector<double>& D,
                                LensDistortion* distortion, std::string* why_not) {
  if (!std::all_of(D.begin(), D.end(), [](double d) { return std::isfinite(d); })) {
    *why_not = "camera_info D holds a value that is not finite";
    return false;
  }
  if (std::all_of(D.begin(), D.end(), [](double d) { return d == 0.0; })) return true;
  if (model == "equidistant" && D.size() == 4) {
    *distortion = {D[0], D[1], 0.0, 0.0, D[2], D[3]};
    distortion->fisheye = true;
    return true;
  }
  const bool plumb_bob = (model == "plumb_bob" || model.empty()) && D.size() == 5;
  const bool rational = model == "rational_polynomial" && D.size() == 8;
  if (!plumb_bob && !rational) {
    *why_not = "camera_info distortion model '" + model + "' with " + std::to_string(D.size()) +
               " coefficients is not supported (plumb_bob with 5, rational_polynomial with 8, "
               "equidistant with 4)";
    return false;
  }
  *distortion = {D[0], D[1], D[2], D[3], D[4]};
  if (rational) distortion->k4 = D[5], distortion->k5 = D[6], distortion->k6 = D[7];
  return true;
}

/// P's left 3x3 block (K') and its fourth column in metres, K'^-1 P[:, 3]; false for a P that is
/// not finite, not K' [I | t] with positive focal lengths, or with Tz (P[11]) not 0.
bool projectionValid(const Matrix34d& P, Eigen::Matrix3d* K_rect, Eigen::Vector3d* t_rect_m,
                     std::string* why_not) {
  *K_rect = P.leftCols<3>();
  if (!intrinsicsValid(K_rect, "P", why_not)) return false;
  const Eigen::Vector3d column = P.col(3) / P(2, 2);
  if (column.z() != 0.0) {
    *why_not = "camera_info P[11] (Tz) is not 0: the stereo cameras are not in one image plane";
    return false;
  }
  *t_rect_m = K_rect->inverse() * column;
  return true;
}

bool rotationValid(const Eigen::Matrix3d& R, std::string* why_not) {
  if (!R.allFinite() || !(R * R.transpose()).isApprox(Eigen::Matrix3d::Identity(), 1e-6) ||
      !(R.determinant() > 0.0)) {
    *why_not = "camera_info R is not a rotation (orthonormal, det +1)";
    return false;
  }
  return true;
}

template <typename Matrix, typename CvMatrix>
Matrix toEigen(const CvMatrix& m) {
  Matrix out;
  cv::cv2eigen(cv::Mat(m), out);
  return out;
}

bool modelFromInfo(const sensor_msgs::CameraInfo& info, image_geometry::PinholeCameraModel* model,
                   std::string* why_not) {
  const bool full_roi = info.roi.width == 0 && info.roi.height == 0 && info.roi.x_offset == 0 &&
                        info.roi.y_offset == 0;
  if (info.binning_x > 1 || info.binning_y > 1 || !full_roi) {
    *why_not = "camera_info with binning or a region of interest is not supported";
    return false;
  }
  try {
    model->fromCameraInfo(info);
  } catch (const std::exception& e) {
    *why_not = std::string("camera_info: ") + e.what();
    return false;
  }
  return true;
}

}  // namespace

bool cameraInfoGeometry(const sensor_msgs::CameraInfo& info, bool rectified,
                        CameraInfoGeometry* geometry, std::string* why_not) {
  image_geometry::PinholeCameraModel model;
  if (!modelFromInfo(info, &model, why_not)) return false;
  CameraInfoGeometry g;
  Eigen::Matrix3d K = toEigen<Eigen::Matrix3d>(model.intrinsicMatrix());
  if (!intrinsicsValid(&K, "K", why_not)) return false;
  const Matrix34d P = toEigen<Matrix34d>(model.projectionMatrix());
  const Eigen::Matrix3d R = toEigen<Eigen::Matrix3d>(model.rotationMatrix());
  if (!P.allFinite() || !R.allFinite()) {
    *why_not = "camera_info P or R holds a value that is not finite";
    return false;
  }
  // Drivers that know no rectification often leave R or P all zero: that is R = I, P = K [I | 0].
  const bool has_P = !P.isZero(), has_R = !R.isZero();
  if (has_P && !projectionValid(P, &g.K_rect, &g.t_rect_m, why_not)) return false;
  if (has_R && !rotationValid(R, why_not)) return false;
  if (!has_P) g.K_rect = K;
  if (has_R) g.R_rect_C = R;
  const cv::Mat_<double>& D_model = model.distortionCoeffs();  // empty for an empty D
  std::vector<double> D;
  for (int i = 0; !D_model.empty() && i < static_cast<int>(D_model.total()); ++i) {
    D.push_back(D_model(i));
  }
  LensDistortion distortion;
  if (!rectified && !distortionFromCoefficients(info.distortion_model, D, &distortion, why_not)) {
    return false;
  }
  const bool rectifies = !g.R_rect_C.isIdentity(1e-12) || !g.K_rect.isApprox(K, 1e-12);
  g.rectified = rectified || (distortion.isZero() && rectifies);
  g.K = g.rectified ? g.K_rect : K;
  if (!g.rectified) g.distortion = distortion;
  *geometry = g;
  return true;
}

namespace {

bool sizeMatches(const sensor_msgs::CameraInfo& info, cv::Size image_size, std::string* why_not) {
  // Sides compared as they are: their product (cv::Size::area) overflows int for large images.
  const bool has_size = image_size.width > 0 && image_size.height > 0;
  if (has_size && (static_cast<int64_t>(info.width) != image_size.width ||
                   static_cast<int64_t>(info.height) != image_size.height)) {
    std::ostringstream message;
    message << "camera_info is " << info.width << "x" << info.height << " but the image is "
            << image_size.width << "x" << image_size.height;
    *why_not = message.str();
    return false;
  }
  return true;
}

/// The camera, refused (as the hull refuses its views) when its lens distortion folds over within
/// the camera_info's image.
bool makeCamera(const CameraInfoGeometry& g, const sensor_msgs::CameraInfo& info,
                const Eigen::Matrix3d& R_I_W, const Eigen::Vector3d& t_I_W, PinholeCamera* camera,
                std::string* why_not) {
  if (!g.distortion.isZero() &&
      (info.width > limits::kMaxImageSidePx || info.height > limits::kMaxImageSidePx)) {
    *why_not = "camera_info is " + std::to_string(info.width) + "x" + std::to_string(info.height) +
               ", beyond the image side limit of 65536";
    return false;
  }
  try {
    *camera = PinholeCamera(g.K, R_I_W, t_I_W).withDistortion(g.distortion);
    requireUnfoldedDistortion(info.header.frame_id, *camera, static_cast<int>(info.width),
                              static_cast<int>(info.height));
  } catch (const std::invalid_argument& e) {
    *why_not = std::string("camera: ") + e.what();
    return false;
  }
  return true;
}

}  // namespace

bool cameraFromInfo(const sensor_msgs::CameraInfo& info, const Eigen::Isometry3d& T_W_C,
                    cv::Size image_size, PinholeCamera* camera, std::string* why_not,
                    bool rectified) {
  CameraInfoGeometry g;
  if (!cameraInfoGeometry(info, rectified, &g, why_not)) return false;
  if (!sizeMatches(info, image_size, why_not)) return false;
  if (!T_W_C.matrix().allFinite()) {
    *why_not = "camera pose is not finite";
    return false;
  }
  const Eigen::Isometry3d T_C_W = T_W_C.inverse();
  // A rectified image's camera looks along the rectified frame, R from the camera's frame.
  const Eigen::Matrix3d R_I_C = g.rectified ? g.R_rect_C : Eigen::Matrix3d::Identity();
  return makeCamera(g, info, R_I_C * T_C_W.linear(), R_I_C * T_C_W.translation(), camera, why_not);
}

bool sharedFrameStereo(const sensor_msgs::CameraInfo& left_info,
                       const sensor_msgs::CameraInfo& right_info, cv::Size left_size,
                       cv::Size right_size, bool rectified, PinholeCamera* left,
                       PinholeCamera* right, std::string* why_not) {
  CameraInfoGeometry g[2];
  const sensor_msgs::CameraInfo* infos[2] = {&left_info, &right_info};
  const cv::Size sizes[2] = {left_size, right_size};
  PinholeCamera* cameras[2] = {left, right};
  for (int i = 0; i < 2; ++i) {
    if (!cameraInfoGeometry(*infos[i], rectified, &g[i], why_not) ||
        !sizeMatches(*infos[i], sizes[i], why_not)) {
      *why_not = std::string(i == 0 ? "left " : "right ") + *why_not;
      return false;
    }
  }
  // The rectified frame of the pair is the left camera's R applied to the shared frame; each
  // P's fourth column puts its camera in it; a raw image's camera turns back by its own R.
  for (int i = 0; i < 2; ++i) {
    const Eigen::Matrix3d R_I_rect =
        g[i].rectified ? Eigen::Matrix3d::Identity() : Eigen::Matrix3d(g[i].R_rect_C.transpose());
    if (!makeCamera(g[i], *infos[i], R_I_rect * g[0].R_rect_C, R_I_rect * g[i].t_rect_m, cameras[i],
                    why_not)) {
      return false;
    }
  }
  return true;
}

}  // namespace ros_conversions
}  // namespace sift_hull
