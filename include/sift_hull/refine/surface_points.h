#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "sift_hull/geometry/camera.h"
#include "sift_hull/hull/octree.h"
#include "sift_hull/settings.h"

namespace sift_hull {

/// The kept matches of one pair of calibrated views: raw pixels (as SIFT found them), one entry
/// per match in each vector, and optionally each match's keypoint index in its view (the same
/// index in two pairs: the same feature), which lets pairs confirm one another.
struct PairMatches {
  uint32_t left_view = 0, right_view = 0;  ///< indices into the camera list
  std::vector<Eigen::Vector2d> left_px, right_px;
  std::vector<int> left_keypoint, right_keypoint;  ///< empty, or one per match
};

/// When a triangulated match counts as a point of the surface.
struct SurfacePointConfig {
  /// Largest reprojection error in either view of the pair, pixels.
  double max_reprojection_px = 1.0;
  /// Points of two pairs that share a feature (a keypoint of one view) must lie this close, in
  /// finest voxels of the hull, to confirm each other.
  double confirm_radius_voxels = 2.0;
};
/// Its settings: names, units, ranges, help (sift_hull/settings.h).
template <>
const SettingTable<SurfacePointConfig>& settingsOf<SurfacePointConfig>();

/// Throws std::invalid_argument naming the first bad field.
void validate(const SurfacePointConfig& config);

/// A point on the object's surface and the views that saw it: each view's line of sight to it is
/// empty space.
struct SurfacePoint {
  Eigen::Vector3d X_W = Eigen::Vector3d::Zero();
  double reprojection_px = 0.0;  ///< the larger of its pair's two errors
  /// Standard deviation of its position along the lines of sight, metres: the reprojection error
  /// (at least half a pixel) over the focal length, times the depth, over the sine of the angle
  /// between the pair's two rays.
  double depth_sigma_m = 0.0;
  std::vector<uint32_t> views;  ///< its pair's views and those of the pairs that confirm it
};

/// How many points each test let through, in order.
struct SurfacePointCounts {
  size_t triangulated = 0;  ///< in front of both cameras
  size_t reprojected = 0;   ///< within max_reprojection_px in both views
  size_t inside_hull = 0;   ///< in an occupied cell of the hull
  size_t confirmed = 0;     ///< by another pair that saw the same feature
  size_t kept = 0;          ///< confirmed, or seen by one pair only (nothing to contradict them)
};

/// One pair's matches triangulated (DLT on ideal pixels), in the cameras' frame, each with its
/// reprojection error, depth sigma and the pair's two views (left_view, right_view); matches at
/// infinity or behind a camera are left out. Throws std::invalid_argument for vectors of
/// different lengths.
std::vector<SurfacePoint> triangulatePair(const PinholeCamera& left, const PinholeCamera& right,
                                          const PairMatches& pair);

/// The depth sigma of a point seen by two cameras with a reprojection error (SurfacePoint).
double depthSigma(const PinholeCamera& a, const PinholeCamera& b, const Eigen::Vector3d& X,
                  double reprojection_px);

/// Triangulates every pair's matches (DLT on ideal pixels) and keeps the points that are
/// consistent: small reprojection errors, inside the hull, and where more than two views see the
/// feature (its keypoint matched in more than one pair), confirmed by another pair's point of it
/// within confirm_radius_voxels; such a point carries the views of every pair that confirms it,
/// and one no other pair confirms is left out. Throws std::invalid_argument for a view index
/// beyond `cameras` or a pair whose vectors differ in length.
std::vector<SurfacePoint> surfacePoints(const std::vector<PinholeCamera>& cameras,
                                        const std::vector<PairMatches>& pairs,
                                        const VisualHull& hull, const SurfacePointConfig& config,
                                        SurfacePointCounts* counts = nullptr);

}  // namespace sift_hull
