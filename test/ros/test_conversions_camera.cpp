// camera_info as image_geometry defines it, without a ROS master: raw images (K, D, rational
// terms included), rectified ones (P and R), and stereo pairs in one frame whose baseline is in
// the right P (stereo_image_proc's convention), checked against the cameras that made them and,
// for a rendered pair, by matching, the epipolar filter and triangulation onto the scene.

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>

#include "lib/conversions.h"
#include "sift_hull/eval/match_evaluation.h"
#include "sift_hull/features/matching.h"
#include "sift_hull/features/triangulation.h"
#include "sift_hull/filters/filter.h"
#include "sift_hull/synthetic/scene.h"
#include "sift_hull/synthetic/shape.h"

namespace sift_hull {
namespace {

namespace rc = ros_conversions;

const Eigen::Matrix3d kK = (Eigen::Matrix3d() << 500, 0, 160, 0, 510, 120, 0, 0, 1).finished();

sensor_msgs::CameraInfo info(const Eigen::Matrix3d& K, const std::vector<double>& D,
                             const Eigen::Matrix3d& R, const Matrix34d& P) {
  sensor_msgs::CameraInfo message;
  message.header.frame_id = "stereo";
  message.width = 320, message.height = 240;
  message.distortion_model = D.size() == 8 ? "rational_polynomial" : "plumb_bob";
  message.D = D;
  for (int i = 0; i < 9; ++i) message.K[i] = K(i / 3, i % 3), message.R[i] = R(i / 3, i % 3);
  for (int i = 0; i < 12; ++i) message.P[i] = P(i / 4, i % 4);
  return message;
}

Matrix34d projection(const Eigen::Matrix3d& K, const Eigen::Vector3d& column) {
  return (Matrix34d() << K, column).finished();
}

Eigen::Vector2d pixelOf(const Matrix34d& P, const Eigen::Vector3d& X) {
  const Eigen::Vector3d x = P * X.homogeneous();
  return x.head<2>() / x.z();
}

std::string refusal(const sensor_msgs::CameraInfo& message, bool rectified = false) {
  PinholeCamera camera;
  std::string why_not;
  const bool ok = rc::cameraFromInfo(message, Eigen::Isometry3d::Identity(), {320, 240}, &camera,
                                     &why_not, rectified);
  return ok ? "" : why_not;
}

const Eigen::Matrix3d kRect = Eigen::AngleAxisd(0.05, Eigen::Vector3d::UnitY()).toRotationMatrix();
const Eigen::Matrix3d kKRect = (Eigen::Matrix3d() << 480, 0, 150, 0, 480, 118, 0, 0, 1).finished();

TEST(CameraInfoGeometry, RationalDistortionRoundTrips) {
  const LensDistortion lens{0.6, -0.2, 0.0008, -0.0005, 0.03, 0.9, -0.15, 0.04};
  const PinholeCamera camera =
      PinholeCamera(kK, Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero()).withDistortion(lens);
  const sensor_msgs::CameraInfo message = rc::cameraInfoMessage(camera, {320, 240}, {});
  EXPECT_EQ(message.distortion_model, "rational_polynomial");
  ASSERT_EQ(message.D.size(), 8u);
  EXPECT_EQ(message.D[5], 0.9);
  PinholeCamera back;
  std::string why_not;
  ASSERT_TRUE(
      rc::cameraFromInfo(message, Eigen::Isometry3d::Identity(), {320, 240}, &back, &why_not));
  const Eigen::Vector3d X(0.3, -0.2, 1.0);
  EXPECT_LT((back.project(X) - camera.project(X)).norm(), 1e-12);
  EXPECT_EQ(back.distortion().k6, 0.04);
}

TEST(CameraInfoGeometry, FisheyeDistortionRoundTripsAndMatchesOpenCvFisheye) {
  LensDistortion lens{0.05, -0.01, 0.0, 0.0, 0.002, -0.0004};
  lens.fisheye = true;
  const PinholeCamera camera =
      PinholeCamera(kK, Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero()).withDistortion(lens);
  const sensor_msgs::CameraInfo message = rc::cameraInfoMessage(camera, {320, 240}, {});
  EXPECT_EQ(message.distortion_model, "equidistant");
  EXPECT_EQ(message.D, (std::vector<double>{0.05, -0.01, 0.002, -0.0004}));
  PinholeCamera back;
  std::string why_not;
  ASSERT_TRUE(
      rc::cameraFromInfo(message, Eigen::Isometry3d::Identity(), {320, 240}, &back, &why_not))
      << why_not;
  const std::vector<cv::Point3d> points = {{0.3, -0.2, 1.0}, {-0.9, 0.6, 1.0}, {0.0, 0.0, 2.0}};
  cv::Mat K_cv, rvec = cv::Mat::zeros(3, 1, CV_64F), tvec = cv::Mat::zeros(3, 1, CV_64F);
  cv::eigen2cv(kK, K_cv);
  const cv::Mat D = (cv::Mat_<double>(1, 4) << 0.05, -0.01, 0.002, -0.0004);
  std::vector<cv::Point2d> expected;
  cv::fisheye::projectPoints(points, expected, rvec, tvec, K_cv, D);
  for (size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3d X(points[i].x, points[i].y, points[i].z);
    const Eigen::Vector2d pixel = back.project(X);
    EXPECT_LT((pixel - Eigen::Vector2d(expected[i].x, expected[i].y)).norm(), 1e-9) << i;
    EXPECT_LT((back.undistortPixel(pixel).value() - back.projectIdeal(X)).norm(), 1e-8) << i;
  }
}

TEST(CameraInfoGeometry, NoDistortionWithARectifyingRAndPIsTheRectifiedCameraOfP) {
  const sensor_msgs::CameraInfo message =
      info(kK, {0, 0, 0, 0, 0}, kRect, projection(kKRect, Eigen::Vector3d::Zero()));
  rc::CameraInfoGeometry g;
  std::string why_not;
  ASSERT_TRUE(rc::cameraInfoGeometry(message, false, &g, &why_not)) << why_not;
  EXPECT_TRUE(g.rectified);
  EXPECT_TRUE(g.K.isApprox(kKRect));
  PinholeCamera camera;
  ASSERT_TRUE(
      rc::cameraFromInfo(message, Eigen::Isometry3d::Identity(), {320, 240}, &camera, &why_not));
  // A point of the camera's frame is seen at P (R X): image_geometry's rectified projection.
  const Eigen::Vector3d X_C(0.2, -0.1, 2.0);
  EXPECT_LT((camera.project(X_C) - pixelOf(projection(kKRect, {0, 0, 0}), kRect * X_C)).norm(),
            1e-9);
  // The same K and P, R = I: an ordinary pinhole (K), not a rectified image.
  ASSERT_TRUE(rc::cameraInfoGeometry(
      info(kK, {}, Eigen::Matrix3d::Identity(), projection(kK, {0, 0, 0})), false, &g, &why_not));
  EXPECT_FALSE(g.rectified);
  EXPECT_TRUE(g.K.isApprox(kK));
}

TEST(CameraInfoGeometry, RectifiedFlagUsesPWhateverDSays) {
  // image_proc's image_rect is published beside the raw image's camera_info, D included.
  const sensor_msgs::CameraInfo message =
      info(kK, {-0.3, 0.1, 0.001, 0.0, 0.0}, kRect, projection(kKRect, Eigen::Vector3d::Zero()));
  rc::CameraInfoGeometry raw, rectified;
  std::string why_not;
  ASSERT_TRUE(rc::cameraInfoGeometry(message, false, &raw, &why_not));
  ASSERT_TRUE(rc::cameraInfoGeometry(message, true, &rectified, &why_not));
  EXPECT_FALSE(raw.rectified);
  EXPECT_TRUE(raw.K.isApprox(kK));
  EXPECT_EQ(raw.distortion.k1, -0.3);
  EXPECT_TRUE(rectified.rectified);
  EXPECT_TRUE(rectified.K.isApprox(kKRect));
  EXPECT_TRUE(rectified.distortion.isZero());
  // A fisheye raw image is OpenCV's fisheye lens; its rectified image has no lens.
  sensor_msgs::CameraInfo fisheye = message;
  fisheye.distortion_model = "equidistant";
  fisheye.D = {0.1, 0.01, -0.002, 0.0005};
  ASSERT_TRUE(rc::cameraInfoGeometry(fisheye, false, &raw, &why_not)) << why_not;
  EXPECT_TRUE(raw.distortion.fisheye);
  EXPECT_EQ(raw.distortion.k3, -0.002);
  EXPECT_EQ(raw.distortion.k4, 0.0005);
  ASSERT_TRUE(rc::cameraInfoGeometry(fisheye, true, &rectified, &why_not));
  EXPECT_TRUE(rectified.distortion.isZero());
}

TEST(CameraInfoGeometry, RefusesAnInconsistentPOrR) {
  const sensor_msgs::CameraInfo good = info(kK, {}, kRect, projection(kKRect, {0, 0, 0}));
  EXPECT_EQ(refusal(good), "");
  sensor_msgs::CameraInfo bad = good;
  bad.P[11] = 0.3;
  EXPECT_EQ(refusal(bad),
            "camera_info P[11] (Tz) is not 0: the stereo cameras are not in one image plane");
  bad = good, bad.P[0] = std::nan("");
  EXPECT_EQ(refusal(bad), "camera_info P or R holds a value that is not finite");
  bad = good, bad.P[5] = 0.0;
  EXPECT_EQ(refusal(bad), "camera_info P is not upper triangular with positive focal lengths");
  bad = good, bad.P[10] = 0.0;
  EXPECT_EQ(refusal(bad), "camera_info P[10] is 0");
  bad = good, bad.R[0] = 2.0;
  EXPECT_EQ(refusal(bad), "camera_info R is not a rotation (orthonormal, det +1)");
  bad = good, bad.binning_x = 2;
  EXPECT_EQ(refusal(bad), "camera_info with binning or a region of interest is not supported");
  bad = good, bad.K[4] = 0.0;
  EXPECT_EQ(refusal(bad), "camera_info K is not upper triangular with positive focal lengths");
  // All-zero R and P (drivers that know no rectification): the raw K alone.
  bad = good;
  bad.R.fill(0.0), bad.P.fill(0.0);
  EXPECT_EQ(refusal(bad), "");
}

TEST(CameraInfoGeometry, RefusesADistortionThatFoldsOverWithinTheImage) {
  // k1 = -3 folds the model over at r^2 = 1/9, inside this 320x240 image's corners (r^2 = 0.16);
  // the camera is refused as the hull refuses such a view (requireUnfoldedDistortion).
  sensor_msgs::CameraInfo folded =
      info(kK, {-3.0, 0, 0, 0, 0}, Eigen::Matrix3d::Zero(), Matrix34d::Zero());
  folded.header.frame_id = "left";
  EXPECT_EQ(refusal(folded),
            "camera: view 'left': its lens distortion folds over within its 320x240 image (no "
            "one-to-one undistortion): check the coefficients and the image size");
  PinholeCamera left, right;
  std::string why_not;
  EXPECT_FALSE(rc::sharedFrameStereo(folded, folded, {320, 240}, {320, 240}, false, &left, &right,
                                     &why_not));
  EXPECT_NE(why_not.find("folds over within its 320x240 image"), std::string::npos) << why_not;
  sensor_msgs::CameraInfo mild = folded;
  mild.D = {-0.1, 0.01, 0, 0, 0};
  EXPECT_EQ(refusal(mild), "");
}

TEST(SharedFrameStereo, TheRightCameraSitsAtTheBaselineOfItsP) {
  const double baseline_m = 0.12, fx = kKRect(0, 0);
  const sensor_msgs::CameraInfo left = info(kK, {}, kRect, projection(kKRect, {0, 0, 0}));
  const sensor_msgs::CameraInfo right =
      info(kK, {}, kRect, projection(kKRect, {-fx * baseline_m, 0, 0}));
  PinholeCamera l, r;
  std::string why_not;
  ASSERT_TRUE(rc::sharedFrameStereo(left, right, {320, 240}, {320, 240}, false, &l, &r, &why_not))
      << why_not;
  // Centres in the shared frame: the right one B along the rectified x axis.
  EXPECT_LT(l.centre().norm(), 1e-12);
  EXPECT_LT((r.centre() - kRect.transpose() * Eigen::Vector3d(baseline_m, 0, 0)).norm(), 1e-12);
  const Eigen::Vector3d X(0.3, 0.2, 2.5);
  EXPECT_LT((l.project(X) - pixelOf(projection(kKRect, {0, 0, 0}), kRect * X)).norm(), 1e-9);
  const Eigen::Vector2d right_px = pixelOf(projection(kKRect, {-fx * baseline_m, 0, 0}), kRect * X);
  EXPECT_LT((r.project(X) - right_px).norm(), 1e-9);
  // A rectified pair: same row, disparity fx B / Z.
  EXPECT_NEAR(l.project(X).y(), r.project(X).y(), 1e-9);
  EXPECT_NEAR(l.project(X).x() - r.project(X).x(), fx * baseline_m / (kRect * X).z(), 1e-9);
}

// ---- a rendered pair in one frame, through matching and triangulation --------------------------

/// What the epipolar filter and triangulation make of a pair of cameras in the left camera's
/// frame: the share of ground-truth-correct matches kept, and of points within 2 % of the depth.
struct PairScore {
  size_t correct = 0, points = 0;
  double correct_kept = 0.0, on_surface = 0.0;
};

PairScore scorePair(const RenderedView& a, const RenderedView& b, const PinholeCamera& left,
                    const PinholeCamera& right) {
  PutativeMatches matches = matchImages(a.image, b.image, SiftConfig{}, MatchConfig{});
  calibratePair(&matches, left, right);
  const FilterResult kept = makeFilter("epipolar", FilterConfigs{})->apply(matches);
  const std::vector<MatchTruth> truth =
      judgeBySceneDepth(matches, {a.view.camera, a.depth}, {b.view.camera, b.depth});
  PairScore score;
  size_t kept_correct = 0;
  for (size_t m = 0; m < truth.size(); ++m) {
    if (truth[m] != MatchTruth::kCorrect) continue;
    ++score.correct;
    kept_correct += kept.keep[m];
  }
  score.correct_kept = static_cast<double>(kept_correct) / std::max<size_t>(score.correct, 1);
  size_t on_surface = 0;
  for (const Eigen::Vector3d& X : triangulateMatches(left, right, matches, kept.keep)) {
    const Eigen::Vector2d pixel = left.project(X);
    const int u = static_cast<int>(std::lround(pixel.x())),
              v = static_cast<int>(std::lround(pixel.y()));
    ++score.points;
    if (u < 0 || v < 0 || u >= a.depth.cols || v >= a.depth.rows) continue;
    on_surface += std::abs(a.depth.at<float>(v, u) - left.depth(X)) < 0.02 * left.depth(X);
  }
  score.on_surface = static_cast<double>(on_surface) / std::max<size_t>(score.points, 1);
  ::testing::Test::RecordProperty("correct_matches_kept", std::to_string(kept_correct) + " of " +
                                                              std::to_string(score.correct));
  ::testing::Test::RecordProperty("points_within_2_percent", std::to_string(on_surface) + " of " +
                                                                 std::to_string(score.points));
  return score;
}

Eigen::Matrix3d toEigen(const cv::Mat& m) {
  Eigen::Matrix3d out;
  cv::cv2eigen(m, out);
  return out;
}

TEST(SharedFrameStereo, ARawDistortedPairRectifiedByStereoRectifyMatchesAndTriangulates) {
  SceneConfig config;
  config.width_px = 320, config.height_px = 240;
  config.distortion = {-0.12, 0.03, 0.0005, -0.0003, 0.0};
  const RenderedView a = renderSceneView(config, 0), b = renderSceneView(config, 1);
  const PinholeCamera &A = a.view.camera, &B = b.view.camera;
  // The calibration of the pair as camera_calibration writes it: X_b = R X_a + T.
  const Eigen::Matrix3d R_ba = B.R() * A.R().transpose();
  const Eigen::Vector3d T_ba = B.t() - R_ba * A.t();
  cv::Mat K_a, K_b, R, T, R1, R2, P1, P2, Q;
  cv::eigen2cv(Eigen::Matrix3d(A.K()), K_a);
  cv::eigen2cv(Eigen::Matrix3d(B.K()), K_b);
  cv::eigen2cv(R_ba, R);
  cv::eigen2cv(T_ba, T);
  const LensDistortion& d = config.distortion;
  const std::vector<double> D = {d.k1, d.k2, d.p1, d.p2, d.k3};
  cv::stereoRectify(K_a, D, K_b, D, cv::Size(320, 240), R, T, R1, R2, P1, P2, Q);
  Matrix34d P_left, P_right;
  cv::cv2eigen(P1, P_left);
  cv::cv2eigen(P2, P_right);
  const sensor_msgs::CameraInfo left_info = info(A.K(), D, toEigen(R1), P_left);
  const sensor_msgs::CameraInfo right_info = info(B.K(), D, toEigen(R2), P_right);
  PinholeCamera left, right;
  std::string why_not;
  ASSERT_TRUE(rc::sharedFrameStereo(left_info, right_info, {320, 240}, {320, 240}, false, &left,
                                    &right, &why_not))
      << why_not;
  // The cameras of the calibration, in the left camera's frame: raw pixels agree.
  const Eigen::Vector3d X_W(0.1, 0.2, -0.1), X_A = A.toCamera(X_W);
  EXPECT_LT((left.project(X_A) - A.project(X_W)).norm(), 1e-6);
  EXPECT_LT((right.project(X_A) - B.project(X_W)).norm(), 1e-6);
  const PairScore score = scorePair(a, b, left, right);
  ASSERT_GE(score.correct, 30u);
  EXPECT_GE(score.correct_kept, 0.95);
  ASSERT_GE(score.points, 20u);
  EXPECT_GE(score.on_surface, 0.9);
}

TEST(SharedFrameStereo, ARectifiedPairWithTheBaselineInPMatchesAndTriangulates) {
  SceneConfig config;
  config.width_px = 320, config.height_px = 240;
  const Shape shape = Shape::byName(config.shape);
  const CalibratedView left_view = sceneCameras(config, shape)[0];
  const double baseline_m = 0.3;
  CalibratedView right_view = left_view;
  const PinholeCamera& L = left_view.camera;
  right_view.camera = PinholeCamera(L.K(), L.R(), L.t() - Eigen::Vector3d(baseline_m, 0, 0));
  const cv::Size size(320, 240);
  const RenderedView a = renderView(shape, left_view, size, config.seed);
  const RenderedView b = renderView(shape, right_view, size, config.seed);
  const double fx = L.K()(0, 0);
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  PinholeCamera left, right;
  std::string why_not;
  ASSERT_TRUE(rc::sharedFrameStereo(info(L.K(), {}, I, projection(L.K(), {0, 0, 0})),
                                    info(L.K(), {}, I, projection(L.K(), {-fx * baseline_m, 0, 0})),
                                    size, size, false, &left, &right, &why_not))
      << why_not;
  EXPECT_LT((right.centre() - Eigen::Vector3d(baseline_m, 0, 0)).norm(), 1e-12);
  const PairScore score = scorePair(a, b, left, right);
  ASSERT_GE(score.correct, 30u);
  EXPECT_GE(score.correct_kept, 0.95);
  ASSERT_GE(score.points, 20u);
  EXPECT_GE(score.on_surface, 0.9);
}

}  // namespace
}  // namespace sift_hull
