#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "sift_hull/synthetic/shape.h"

namespace sift_hull {

/// The names SceneConfig::support takes: "none", "floor", "turntable".
const std::vector<std::string>& sceneSupports();

/// What a scene's object stands on, and the light that makes it cast a shadow there. World up is
/// +z. With a support the object and the support are lit by one directional light from above, at
/// 40 degrees from the vertical; a support point whose ray toward the light hits the object (or,
/// for a floor point, the disc) gets only the ambient share of the light.
struct SceneSupport {
  bool floor = false;      ///< a textured ground plane z = floor_z ("floor" and "turntable")
  bool turntable = false;  ///< a disc from floor_z up to stand_z, under the object
  double stand_z = 0.0;    ///< where the object stands: its lowest point (the disc's top face)
  double floor_z = 0.0;    ///< stand_z, or for a turntable stand_z less the disc's thickness
  Eigen::Vector2d disc_centre_xy = Eigen::Vector2d::Zero();  ///< under the bounding centre
  double disc_radius_m = 0.0;  ///< 1.6 times the shape's bounding radius (turntable only)
  /// Unit vector toward the light (from the surface), the same for every point.
  Eigen::Vector3d light_W = Eigen::Vector3d::UnitZ();
};

/// Shading of a lit surface: ambient share plus the rest times the cosine to the light.
inline constexpr double kAmbientShading = 0.35;

/// The support `name` (sceneSupports()) under `shape`. Throws std::invalid_argument naming the
/// valid names for an unknown one.
SceneSupport sceneSupport(const Shape& shape, const std::string& name);

/// Where a ray first meets a support: the floor, the disc's top face or its rim.
struct SupportHit {
  enum class Part { kFloor, kDiscTop, kDiscSide };
  Part part = Part::kFloor;
  double distance_m = 0.0;  ///< along the unit ray direction
  Eigen::Vector3d normal_W = Eigen::Vector3d::UnitZ();
};

/// First hit of the ray origin + s * direction (s > 0, unit direction) on the support; false when
/// it misses (always for "none", and for rays that do not go down toward the floor).
bool firstSupportHit(const SceneSupport& support, const Eigen::Vector3d& origin,
                     const Eigen::Vector3d& direction, SupportHit* hit);

/// Whether the support point X_W (of the part `part`) lies in shadow: its ray toward the light
/// hits the shape, or, for a floor point, the disc.
bool supportInShadow(const Shape& shape, const SceneSupport& support, SupportHit::Part part,
                     const Eigen::Vector3d& X_W);

}  // namespace sift_hull
