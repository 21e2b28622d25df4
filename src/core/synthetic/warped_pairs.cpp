#include "sift_hull/synthetic/warped_pairs.h"

#include <Eigen/Dense>
#include <cmath>
#include <opencv2/core/eigen.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "sift_hull/synthetic/scene.h"

namespace sift_hull {
namespace {

/// The left image: view 0 of the default scene on its textured background.
cv::Mat sourceImage() {
  SceneConfig scene;
  scene.background = "textured";
  return renderSceneView(scene, 0).image;
}

/// Rotation by `deg` and scaling by `scale` about `centre`, then a shift.
Eigen::Matrix3d similarity(double deg, double scale, const cv::Point2d& centre,
                           const cv::Point2d& shift) {
  const cv::Mat A = cv::getRotationMatrix2D(centre, -deg, scale);  // OpenCV: positive = CCW
  Eigen::Matrix3d H = Eigen::Matrix3d::Identity();
  for (int r = 0; r < 2; ++r) {
    for (int c = 0; c < 3; ++c) H(r, c) = A.at<double>(r, c);
  }
  H(0, 2) += shift.x, H(1, 2) += shift.y;
  return H;
}

/// Draws each region of the left image warped by its motion, later regions over earlier.
WarpedPair warpRegions(const cv::Mat& left, const cv::Mat& regions,
                       const std::vector<Eigen::Matrix3d>& motions) {
  WarpedPair pair{left, cv::Mat::zeros(left.size(), left.type()), motions, regions,
                  cv::Mat::zeros(left.size(), CV_8UC1)};
  for (size_t k = 0; k < motions.size(); ++k) {
    cv::Mat H, warped, mask, inside = (regions == static_cast<int>(k));
    cv::eigen2cv(motions[k], H);
    cv::warpPerspective(left, warped, H, left.size(), cv::INTER_LINEAR, cv::BORDER_CONSTANT);
    cv::warpPerspective(inside, mask, H, left.size(), cv::INTER_NEAREST, cv::BORDER_CONSTANT);
    warped.copyTo(pair.right, mask);
    pair.right_owner.setTo(static_cast<int>(k + 1), mask);
  }
  return pair;
}

}  // namespace

WarpedPair rotationZoomPair(double rotation_deg, double scale) {
  const cv::Mat left = sourceImage();
  const cv::Point2d centre(left.cols / 2.0, left.rows / 2.0);
  return warpRegions(left, cv::Mat::zeros(left.size(), CV_8UC1),
                     {similarity(rotation_deg, scale, centre, {0, 0})});
}

WarpedPair opticalZoomPair(double rotation_deg, double zoom) {
  if (!(zoom >= 1.0 && zoom <= 12.0)) {
    throw std::invalid_argument("opticalZoomPair: the zoom must lie in [1, 12]");
  }
  SceneConfig scene;
  scene.background = "textured";
  const cv::Size size(scene.width_px, scene.height_px);
  scene.width_px = static_cast<int>(std::lround(zoom * size.width));
  scene.height_px = static_cast<int>(std::lround(zoom * size.height));
  const cv::Mat fine = renderSceneView(scene, 0).image;
  cv::Mat left;
  cv::resize(fine, left, size, 0.0, 0.0, cv::INTER_AREA);
  // A left pixel to the fine render's (pixel centres at integers: u' = s (u + 0.5) - 0.5).
  Eigen::Matrix3d to_fine = Eigen::Matrix3d::Identity();
  to_fine(0, 0) = static_cast<double>(fine.cols) / size.width;
  to_fine(1, 1) = static_cast<double>(fine.rows) / size.height;
  to_fine(0, 2) = 0.5 * to_fine(0, 0) - 0.5;
  to_fine(1, 2) = 0.5 * to_fine(1, 1) - 0.5;
  // The right image: the fine render's centre at its own resolution, turned about it.
  const cv::Point2d fine_centre((fine.cols - 1) / 2.0, (fine.rows - 1) / 2.0);
  const cv::Point2d centre((size.width - 1) / 2.0, (size.height - 1) / 2.0);
  const Eigen::Matrix3d turn = similarity(rotation_deg, 1.0, fine_centre, centre - fine_centre);
  cv::Mat H, seen;
  cv::eigen2cv(turn, H);
  WarpedPair pair{left, cv::Mat(), {turn * to_fine}, cv::Mat::zeros(size, CV_8UC1), cv::Mat()};
  cv::warpPerspective(fine, pair.right, H, size, cv::INTER_LINEAR, cv::BORDER_CONSTANT);
  cv::warpPerspective(cv::Mat(fine.size(), CV_8UC1, cv::Scalar(1)), pair.right_owner, H, size,
                      cv::INTER_NEAREST, cv::BORDER_CONSTANT);
  return pair;
}

WarpedPair twoMotionPair() {
  const cv::Mat left = sourceImage();
  cv::Mat regions = cv::Mat::zeros(left.size(), CV_8UC1);
  regions(cv::Rect(left.cols / 2, 0, left.cols - left.cols / 2, left.rows)).setTo(1);
  const cv::Point2d a(left.cols * 0.25, left.rows * 0.5), b(left.cols * 0.75, left.rows * 0.5);
  return warpRegions(
      left, regions,
      {similarity(8.0, 1.05, a, {-40.0, 15.0}), similarity(-15.0, 0.85, b, {45.0, -20.0})});
}

std::vector<MatchTruth> judgeByMotions(const PutativeMatches& input, const WarpedPair& pair,
                                       double max_error_px) {
  std::vector<MatchTruth> truth(input.matches.size(), MatchTruth::kWrong);
  for (size_t m = 0; m < input.matches.size(); ++m) {
    if (!input.hasFinitePositions(m)) continue;
    const cv::Point2f a = input.left(m).pt, b = input.right(m).pt;
    const int ax = static_cast<int>(std::lround(a.x)), ay = static_cast<int>(std::lround(a.y));
    if (ax < 0 || ay < 0 || ax >= pair.left_region.cols || ay >= pair.left_region.rows) continue;
    const int region = pair.left_region.at<uint8_t>(ay, ax);
    const Eigen::Vector2d expected =
        (pair.motions[region] * Eigen::Vector3d(a.x, a.y, 1.0)).hnormalized();
    const int ex = static_cast<int>(std::lround(expected.x()));
    const int ey = static_cast<int>(std::lround(expected.y()));
    if (ex < 0 || ey < 0 || ex >= pair.right_owner.cols || ey >= pair.right_owner.rows) continue;
    if (pair.right_owner.at<uint8_t>(ey, ex) != region + 1) continue;
    const double error = (expected - Eigen::Vector2d(b.x, b.y)).norm();
    if (error <= max_error_px) truth[m] = MatchTruth::kCorrect;
  }
  return truth;
}

}  // namespace sift_hull
