#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "sift_hull/geometry/camera.h"
#include "sift_hull/hull/bounding_box.h"

namespace sift_hull {
namespace {

constexpr int kWidth = 640;
constexpr int kHeight = 480;
constexpr double kCameraDistance = 5.0;
constexpr double kContainmentTolerance = 1e-6;

/// Whether the ray from origin along the unit direction meets the object.
using RayTest = std::function<bool(const Eigen::Vector3d&, const Eigen::Vector3d&)>;

Eigen::Matrix3d testK(double cx = 320.0, double cy = 240.0) {
  Eigen::Matrix3d K;
  K << 500.0, 0.0, cx, 0.0, 500.0, cy, 0.0, 0.0, 1.0;
  return K;
}

/// A camera at `centre` looking at `target`, with world `up` pointing up in the image.
PinholeCamera lookingAt(const Eigen::Vector3d& centre, const Eigen::Vector3d& target,
                        const Eigen::Vector3d& up, const Eigen::Matrix3d& K = testK()) {
  const Eigen::Vector3d forward = (target - centre).normalized();
  const Eigen::Vector3d down = -(up - up.dot(forward) * forward).normalized();
  Eigen::Matrix3d R;
  R.row(0) = down.cross(forward).transpose();
  R.row(1) = down.transpose();
  R.row(2) = forward.transpose();
  return PinholeCamera::fromCentre(K, R, centre);
}

/// Cameras evenly spaced on a circle in the x-z plane, looking at the origin.
std::vector<PinholeCamera> ringCameras(int count, const Eigen::Matrix3d& K = testK()) {
  std::vector<PinholeCamera> cameras;
  for (int i = 0; i < count; ++i) {
    const double angle = 2.0 * M_PI * i / count;
    const Eigen::Vector3d centre(std::cos(angle), 0.0, std::sin(angle));
    cameras.push_back(
        lookingAt(kCameraDistance * centre, Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitY(), K));
  }
  return cameras;
}

/// Cameras on a Fibonacci spiral over the sphere of directions, looking at the origin.
std::vector<PinholeCamera> sphereCameras(int count) {
  std::vector<PinholeCamera> cameras;
  const double golden_angle = M_PI * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < count; ++i) {
    const double y = 1.0 - 2.0 * (i + 0.5) / count;
    const double radius = std::sqrt(1.0 - y * y);
    const Eigen::Vector3d direction(radius * std::cos(golden_angle * i), y,
                                    radius * std::sin(golden_angle * i));
    const Eigen::Vector3d up =
        std::abs(y) > 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
    cameras.push_back(lookingAt(kCameraDistance * direction, Eigen::Vector3d::Zero(), up));
  }
  return cameras;
}

bool rayHitsUnitSphere(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction) {
  const Eigen::Vector3d to_centre = -origin;
  const double along = to_centre.dot(direction);
  return along > 0.0 && to_centre.squaredNorm() - along * along < 1.0;
}

/// Slab test against the axis-aligned box [-half_extents, half_extents].
RayTest rayHitsBox(const Eigen::Vector3d& half_extents) {
  return [half_extents](const Eigen::Vector3d& origin, const Eigen::Vector3d& direction) {
    double enter = 0.0;
    double leave = INFINITY;
    for (int axis = 0; axis < 3; ++axis) {
      const double a = (-half_extents(axis) - origin(axis)) / direction(axis);
      const double b = (half_extents(axis) - origin(axis)) / direction(axis);
      enter = std::max(enter, std::min(a, b));
      leave = std::min(leave, std::max(a, b));
    }
    return enter < leave;
  };
}

cv::Mat renderMask(const PinholeCamera& camera, const RayTest& hits) {
  cv::Mat mask(kHeight, kWidth, CV_8UC1, cv::Scalar(0));
  for (int v = 0; v < kHeight; ++v) {
    for (int u = 0; u < kWidth; ++u) {
      const Eigen::Vector3d direction = camera.rayDirection(Eigen::Vector2d(u, v));
      if (hits(camera.centre(), direction)) mask.at<uint8_t>(v, u) = 255;
    }
  }
  return mask;
}

std::vector<SilhouetteBounds> silhouettesOf(const std::vector<PinholeCamera>& cameras,
                                            const RayTest& hits, bool border_bounds_object) {
  std::vector<SilhouetteBounds> bounds;
  for (const PinholeCamera& camera : cameras) {
    bounds.push_back(silhouetteBounds(renderMask(camera, hits), border_bounds_object));
  }
  return bounds;
}

/// Expects the box to hold [-half_extents, half_extents] and returns by how much it exceeds it at
/// most, over the six sides, relative to the half extent on that axis.
double largestRelativeExcess(const Box3d& box, const Eigen::Vector3d& half_extents) {
  EXPECT_TRUE(box.contains(half_extents, kContainmentTolerance)) << box.max_W.transpose();
  EXPECT_TRUE(box.contains(-half_extents, kContainmentTolerance)) << box.min_W.transpose();
  const Eigen::Vector3d above = (box.max_W - half_extents).cwiseQuotient(half_extents);
  const Eigen::Vector3d below = (-half_extents - box.min_W).cwiseQuotient(half_extents);
  return std::max(above.maxCoeff(), below.maxCoeff());
}

/// Runs hullBoundingBox, expects a HullBoxError for the given reason and returns its message.
std::string expectHullBoxError(HullBoxError::Reason expected,
                               const std::vector<PinholeCamera>& cameras,
                               const std::vector<SilhouetteBounds>& bounds,
                               const std::vector<std::string>& names = {}) {
  try {
    const Box3d box = hullBoundingBox(cameras, bounds, names);
    ADD_FAILURE() << "no HullBoxError; box " << box.min_W.transpose() << " to "
                  << box.max_W.transpose();
  } catch (const HullBoxError& error) {
    EXPECT_EQ(static_cast<int>(error.reason()), static_cast<int>(expected)) << error.what();
    return error.what();
  }
  return "";
}

TEST(Box3d, ContainsWithTolerance) {
  Box3d box;
  box.min_W = Eigen::Vector3d(-1.0, 0.0, 2.0);
  box.max_W = Eigen::Vector3d(1.0, 3.0, 4.0);
  EXPECT_TRUE(box.contains(Eigen::Vector3d(0.0, 1.0, 3.0)));
  EXPECT_TRUE(box.contains(Eigen::Vector3d(1.0, 3.0, 4.0)));
  EXPECT_FALSE(box.contains(Eigen::Vector3d(1.01, 1.0, 3.0)));
  EXPECT_TRUE(box.contains(Eigen::Vector3d(1.01, 1.0, 3.0), 0.02));
  EXPECT_FALSE(box.contains(Eigen::Vector3d(0.0, 1.0, 1.97), 0.02));
  EXPECT_EQ(box.size(), Eigen::Vector3d(2.0, 3.0, 2.0));
  EXPECT_EQ(box.centre(), Eigen::Vector3d(0.0, 1.5, 3.0));
}

TEST(SilhouetteBounds, EnclosesWholePixelsOfHandMadeMask) {
  cv::Mat mask(8, 10, CV_8UC1, cv::Scalar(0));
  mask(cv::Rect(3, 2, 4, 3)).setTo(1);  // columns 3..6, rows 2..4
  mask.at<uint8_t>(5, 4) = 200;         // one more row below
  const SilhouetteBounds bounds = silhouetteBounds(mask, false);
  EXPECT_FALSE(bounds.empty);
  EXPECT_DOUBLE_EQ(bounds.u_min_px, 2.5);
  EXPECT_DOUBLE_EQ(bounds.u_max_px, 6.5);
  EXPECT_DOUBLE_EQ(bounds.v_min_px, 1.5);
  EXPECT_DOUBLE_EQ(bounds.v_max_px, 5.5);
  EXPECT_EQ(bounds.boundedSides(), 4);
}

TEST(SilhouetteBounds, SinglePixelSpansOnePixel) {
  cv::Mat mask(8, 10, CV_8UC1, cv::Scalar(0));
  mask.at<uint8_t>(3, 5) = 1;
  const SilhouetteBounds bounds = silhouetteBounds(mask, false);
  EXPECT_DOUBLE_EQ(bounds.u_min_px, 4.5);
  EXPECT_DOUBLE_EQ(bounds.u_max_px, 5.5);
  EXPECT_DOUBLE_EQ(bounds.v_min_px, 2.5);
  EXPECT_DOUBLE_EQ(bounds.v_max_px, 3.5);
  EXPECT_EQ(bounds.boundedSides(), 4);
}

TEST(SilhouetteBounds, BorderSidesAreOpenUnlessTheBorderBoundsTheObject) {
  cv::Mat mask(8, 10, CV_8UC1, cv::Scalar(0));
  mask(cv::Rect(0, 4, 3, 4)).setTo(255);  // touches the left and the bottom border
  const SilhouetteBounds open = silhouetteBounds(mask, false);
  EXPECT_FALSE(open.has_u_min);
  EXPECT_TRUE(open.has_u_max);
  EXPECT_TRUE(open.has_v_min);
  EXPECT_FALSE(open.has_v_max);
  EXPECT_EQ(open.boundedSides(), 2);
  const SilhouetteBounds closed = silhouetteBounds(mask, true);
  EXPECT_EQ(closed.boundedSides(), 4);
  EXPECT_DOUBLE_EQ(closed.u_min_px, -0.5);
  EXPECT_DOUBLE_EQ(closed.u_max_px, 2.5);
  EXPECT_DOUBLE_EQ(closed.v_min_px, 3.5);
  EXPECT_DOUBLE_EQ(closed.v_max_px, 7.5);

  mask.setTo(255);
  EXPECT_EQ(silhouetteBounds(mask, false).boundedSides(), 0);
  EXPECT_EQ(silhouetteBounds(mask, true).boundedSides(), 4);
}

TEST(SilhouetteBounds, EmptyMaskHasNoBoundedSide) {
  const cv::Mat mask(8, 10, CV_8UC1, cv::Scalar(0));
  for (bool border_bounds_object : {false, true}) {
    const SilhouetteBounds bounds = silhouetteBounds(mask, border_bounds_object);
    EXPECT_TRUE(bounds.empty);
    EXPECT_EQ(bounds.boundedSides(), 0);
  }
}

TEST(SilhouetteBounds, RejectsEmptyMatAndOtherTypes) {
  EXPECT_THROW(silhouetteBounds(cv::Mat(), false), std::invalid_argument);
  EXPECT_THROW(silhouetteBounds(cv::Mat(4, 4, CV_32FC1, cv::Scalar(1)), false),
               std::invalid_argument);
  EXPECT_THROW(silhouetteBounds(cv::Mat(4, 4, CV_8UC3, cv::Scalar(1, 1, 1)), false),
               std::invalid_argument);
}

TEST(HullBoundingBox, SphereFromRingOfEightViewsIsTight) {
  const std::vector<PinholeCamera> cameras = ringCameras(8);
  const Box3d box = hullBoundingBox(cameras, silhouettesOf(cameras, rayHitsUnitSphere, false));
  // Sixteen tangent planes around the equator and eight tilted ones above and below the poles.
  EXPECT_LT(largestRelativeExcess(box, Eigen::Vector3d::Ones()), 0.03);
}

TEST(HullBoundingBox, SphereFromSixteenViewsOnASphereIsTight) {
  const std::vector<PinholeCamera> cameras = sphereCameras(16);
  const Box3d box = hullBoundingBox(cameras, silhouettesOf(cameras, rayHitsUnitSphere, false));
  EXPECT_LT(largestRelativeExcess(box, Eigen::Vector3d::Ones()), 0.03);
}

TEST(HullBoundingBox, BoxObjectIsContained) {
  const Eigen::Vector3d half_extents(0.5, 0.8, 0.3);
  const std::vector<PinholeCamera> cameras = sphereCameras(16);
  const Box3d box =
      hullBoundingBox(cameras, silhouettesOf(cameras, rayHitsBox(half_extents), false));
  EXPECT_LT(largestRelativeExcess(box, half_extents), 0.5);
}

TEST(HullBoundingBox, SilhouettesCutByTheBorderOpenTheirSide) {
  // The principal point near the left border puts the sphere's left limb outside every image.
  const std::vector<PinholeCamera> cameras = ringCameras(8, testK(60.0, 240.0));
  const std::vector<SilhouetteBounds> open = silhouettesOf(cameras, rayHitsUnitSphere, false);
  for (const SilhouetteBounds& bounds : open) {
    EXPECT_FALSE(bounds.has_u_min);
    EXPECT_EQ(bounds.boundedSides(), 3);
  }
  const Box3d box = hullBoundingBox(cameras, open);
  EXPECT_LT(largestRelativeExcess(box, Eigen::Vector3d::Ones()), 0.1);

  const std::vector<SilhouetteBounds> closed = silhouettesOf(cameras, rayHitsUnitSphere, true);
  for (const SilhouetteBounds& bounds : closed) EXPECT_EQ(bounds.boundedSides(), 4);
  const Box3d cut = hullBoundingBox(cameras, closed);
  EXPECT_LT(cut.max_W.x(), 0.95);  // the image border cuts into the sphere
}

TEST(HullBoundingBox, FacingViewsWithOpenSidesKeepTheBoxBetweenTheCameras) {
  // With one side of each image axis open, only the depth rows keep out the mirror image of each
  // cone behind its camera, which meets the other camera's cone.
  const std::vector<PinholeCamera> cameras = {
      lookingAt({kCameraDistance, 0.0, 0.0}, Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitY(),
                testK(60.0, 40.0)),
      lookingAt({-kCameraDistance, 0.0, 0.0}, Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitY(),
                testK(60.0, 440.0))};
  const std::vector<SilhouetteBounds> bounds = silhouettesOf(cameras, rayHitsUnitSphere, false);
  for (const SilhouetteBounds& view : bounds) ASSERT_EQ(view.boundedSides(), 2);
  const Box3d box = hullBoundingBox(cameras, bounds);
  EXPECT_GE(largestRelativeExcess(box, Eigen::Vector3d::Ones()), 0.0);
  EXPECT_NEAR(box.max_W.x(), kCameraDistance, kContainmentTolerance);
  EXPECT_NEAR(box.min_W.x(), -kCameraDistance, kContainmentTolerance);
}

TEST(HullBoundingBox, OneViewIsTooFew) {
  const std::vector<PinholeCamera> cameras = ringCameras(1);
  expectHullBoxError(HullBoxError::Reason::kTooFewViews, cameras,
                     silhouettesOf(cameras, rayHitsUnitSphere, false));
}

TEST(HullBoundingBox, ViewWithoutBoundedSideDoesNotCount) {
  const std::vector<PinholeCamera> cameras = ringCameras(2);
  std::vector<SilhouetteBounds> bounds = silhouettesOf(cameras, rayHitsUnitSphere, false);
  bounds[1] = silhouetteBounds(cv::Mat(kHeight, kWidth, CV_8UC1, cv::Scalar(255)), false);
  expectHullBoxError(HullBoxError::Reason::kTooFewViews, cameras, bounds);
}

TEST(HullBoundingBox, ParallelOpticalAxesAreUnbounded) {
  const std::vector<PinholeCamera> cameras = {
      PinholeCamera::fromCentre(testK(), Eigen::Matrix3d::Identity(), {-0.5, 0.0, -5.0}),
      PinholeCamera::fromCentre(testK(), Eigen::Matrix3d::Identity(), {0.5, 0.0, -5.0})};
  const std::vector<SilhouetteBounds> bounds = silhouettesOf(cameras, rayHitsUnitSphere, false);
  for (const SilhouetteBounds& view : bounds) ASSERT_EQ(view.boundedSides(), 4);
  const std::string message = expectHullBoxError(HullBoxError::Reason::kUnbounded, cameras, bounds);
  EXPECT_NE(message.find("nearly parallel"), std::string::npos) << message;
}

TEST(HullBoundingBox, NearlyParallelRaysAreUnbounded) {
  // The inner sides of the two cones converge by 2e-9 rad: they meet some 5e8 units ahead.
  const std::vector<PinholeCamera> cameras = {
      PinholeCamera::fromCentre(testK(), Eigen::Matrix3d::Identity(), {-0.5, 0.0, -5.0}),
      PinholeCamera::fromCentre(testK(), Eigen::Matrix3d::Identity(), {0.5, 0.0, -5.0})};
  std::vector<SilhouetteBounds> bounds(2);
  for (SilhouetteBounds& view : bounds) {
    view.empty = false;
    view.has_u_min = view.has_u_max = view.has_v_min = view.has_v_max = true;
    view.v_min_px = 230.0;
    view.v_max_px = 250.0;
  }
  bounds[0].u_min_px = 320.0 + 1e-6;
  bounds[0].u_max_px = 330.0;
  bounds[1].u_min_px = 310.0;
  bounds[1].u_max_px = 320.0;
  expectHullBoxError(HullBoxError::Reason::kUnbounded, cameras, bounds);
}

TEST(HullBoundingBox, ConesThatMissEachOtherAreEmpty) {
  const std::vector<PinholeCamera> cameras = {
      lookingAt({5.0, 0.0, 0.0}, Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitY()),
      lookingAt({0.0, 0.0, 5.0}, Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitY())};
  std::vector<SilhouetteBounds> bounds = silhouettesOf(cameras, rayHitsUnitSphere, false);
  // The second view sees a small blob in its top-left corner: up and away from the first camera.
  cv::Mat corner_blob(kHeight, kWidth, CV_8UC1, cv::Scalar(0));
  corner_blob(cv::Rect(5, 5, 6, 6)).setTo(255);
  bounds[1] = silhouetteBounds(corner_blob, false);
  ASSERT_EQ(bounds[1].boundedSides(), 4);
  const std::string message = expectHullBoxError(HullBoxError::Reason::kEmpty, cameras, bounds);
  EXPECT_NE(message.find("do not intersect"), std::string::npos) << message;
}

TEST(HullBoundingBox, EmptySilhouetteIsNamed) {
  const std::vector<PinholeCamera> cameras = ringCameras(3);
  std::vector<SilhouetteBounds> bounds = silhouettesOf(cameras, rayHitsUnitSphere, false);
  bounds[1] = silhouetteBounds(cv::Mat(kHeight, kWidth, CV_8UC1, cv::Scalar(0)), false);
  const std::string named = expectHullBoxError(HullBoxError::Reason::kEmpty, cameras, bounds,
                                               {"a.png", "b.png", "c.png"});
  EXPECT_NE(named.find("b.png"), std::string::npos) << named;
  const std::string numbered = expectHullBoxError(HullBoxError::Reason::kEmpty, cameras, bounds);
  EXPECT_NE(numbered.find("view 1"), std::string::npos) << numbered;
}

TEST(HullBoundingBox, MismatchedSizesAreInvalidArguments) {
  const std::vector<PinholeCamera> cameras = ringCameras(2);
  const std::vector<SilhouetteBounds> bounds = silhouettesOf(cameras, rayHitsUnitSphere, false);
  EXPECT_THROW(hullBoundingBox(cameras, {bounds[0]}), std::invalid_argument);
  EXPECT_THROW(hullBoundingBox(cameras, bounds, {"only one"}), std::invalid_argument);
  EXPECT_NO_THROW(hullBoundingBox(cameras, bounds, {"a", "b"}));
}

}  // namespace
}  // namespace sift_hull
