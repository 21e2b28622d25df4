#include "sift_hull/synthetic/scene_support.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "synthetic/support_shading.h"
#include "synthetic/texture.h"

namespace sift_hull {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDiscRadiusShare = 1.6;      ///< of the shape's bounding radius
constexpr double kDiscThicknessShare = 0.05;  ///< of the shape's bounding radius
constexpr double kLightFromVerticalDeg = 40.0;

/// Distance from the origin to the segment [a, b] in the plane.
double segmentDistance(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const Eigen::Vector2d ab = b - a;
  const double length2 = ab.squaredNorm();
  const double t = length2 > 0.0 ? std::clamp(-a.dot(ab) / length2, 0.0, 1.0) : 0.0;
  return (a + t * ab).norm();
}

/// Whether the ray X + s * direction (s > 0) can meet the shape's bounding sphere.
bool mayHitShape(const Shape& shape, const Eigen::Vector3d& X, const Eigen::Vector3d& direction) {
  const Eigen::Vector3d to_centre = shape.boundingCentre() - X;
  const double along = to_centre.dot(direction);
  const double radius2 = shape.boundingRadius() * shape.boundingRadius();
  if (along < 0.0 && to_centre.squaredNorm() > radius2) return false;
  return (to_centre - along * direction).squaredNorm() <= radius2;
}

}  // namespace

const std::vector<std::string>& sceneSupports() {
  static const std::vector<std::string> names = {"none", "floor", "turntable"};
  return names;
}

SceneSupport sceneSupport(const Shape& shape, const std::string& name) {
  const std::vector<std::string>& names = sceneSupports();
  if (std::find(names.begin(), names.end(), name) == names.end()) {
    throw std::invalid_argument("support must be none, floor or turntable, not '" + name + "'");
  }
  SceneSupport support;
  Eigen::Vector3d lo, hi;
  shape.boundingBox(&lo, &hi);
  support.floor = name != "none";
  support.turntable = name == "turntable";
  support.stand_z = support.floor_z = lo.z();
  if (support.turntable) {
    support.disc_centre_xy = shape.boundingCentre().head<2>();
    support.disc_radius_m = kDiscRadiusShare * shape.boundingRadius();
    support.floor_z -= kDiscThicknessShare * shape.boundingRadius();
  }
  // From above at 40 degrees, from the side of the light of the scenes without a support.
  const double tilt = kLightFromVerticalDeg * kPi / 180.0, azimuth = std::atan2(0.3, 0.4);
  support.light_W = Eigen::Vector3d(std::sin(tilt) * std::cos(azimuth),
                                    std::sin(tilt) * std::sin(azimuth), std::cos(tilt));
  return support;
}

bool firstSupportHit(const SceneSupport& support, const Eigen::Vector3d& origin,
                     const Eigen::Vector3d& direction, SupportHit* hit) {
  if (!support.floor) return false;
  bool found = false;
  const auto offer = [&](SupportHit::Part part, double distance, const Eigen::Vector3d& normal) {
    if (distance > 0.0 && (!found || distance < hit->distance_m)) {
      *hit = {part, distance, normal};
      found = true;
    }
  };
  if (direction.z() < 0.0 && origin.z() > support.floor_z) {
    offer(SupportHit::Part::kFloor, (support.floor_z - origin.z()) / direction.z(),
          Eigen::Vector3d::UnitZ());
  }
  if (!support.turntable) return found;
  const double radius = support.disc_radius_m;
  const Eigen::Vector2d q = origin.head<2>() - support.disc_centre_xy, e = direction.head<2>();
  if (direction.z() < 0.0 && origin.z() > support.stand_z) {
    const double distance = (support.stand_z - origin.z()) / direction.z();
    if ((q + distance * e).squaredNorm() <= radius * radius) {
      offer(SupportHit::Part::kDiscTop, distance, Eigen::Vector3d::UnitZ());
    }
  }
  // The rim: where the ray enters the vertical cylinder, between the floor and the top face.
  const double a = e.squaredNorm(), b = q.dot(e), c = q.squaredNorm() - radius * radius;
  const double discriminant = b * b - a * c;
  if (a > 1e-18 && discriminant >= 0.0) {
    const double distance = (-b - std::sqrt(discriminant)) / a;
    const double z = origin.z() + distance * direction.z();
    if (z >= support.floor_z && z <= support.stand_z) {
      const Eigen::Vector2d n = (q + distance * e) / radius;
      offer(SupportHit::Part::kDiscSide, distance, Eigen::Vector3d(n.x(), n.y(), 0.0));
    }
  }
  return found;
}

bool supportInShadow(const Shape& shape, const SceneSupport& support, SupportHit::Part part,
                     const Eigen::Vector3d& X_W) {
  const Eigen::Vector3d& light = support.light_W;
  if (part == SupportHit::Part::kFloor && support.turntable) {
    // The ray rises through the disc's slab on a short segment: does that cross the disc?
    const double rise = (support.stand_z - X_W.z()) / light.z();
    const Eigen::Vector2d a = X_W.head<2>() - support.disc_centre_xy;
    if (segmentDistance(a, a + rise * light.head<2>()) <= support.disc_radius_m) return true;
  }
  if (!mayHitShape(shape, X_W, light)) return false;
  RayHit hit;
  return shape.firstHit(X_W, light, &hit);
}

cv::Vec3b shadeSupport(const Shape& shape, const SceneSupport& support, const SupportHit& hit,
                       const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                       double pixel_angle_rad, unsigned seed) {
  const Eigen::Vector3d X_W = origin + hit.distance_m * direction;
  cv::Vec3f albedo;
  switch (hit.part) {
    case SupportHit::Part::kFloor: {
      // A pixel's footprint on the floor, stretched along the view by the grazing angle.
      const double footprint_m =
          hit.distance_m * pixel_angle_rad / std::max(std::abs(direction.z()), 1e-3);
      albedo = floorTexture(X_W.head<2>(), footprint_m, seed + 4241);
      break;
    }
    case SupportHit::Part::kDiscTop:
      albedo =
          discTexture(X_W.head<2>() - support.disc_centre_xy, support.disc_radius_m, seed + 6007);
      break;
    case SupportHit::Part::kDiscSide:
      albedo = cv::Vec3f(0.50f, 0.24f, 0.06f);  // the top's blue, darker
      break;
  }
  const double cosine = std::max(0.0, hit.normal_W.dot(support.light_W));
  double shading = kAmbientShading;
  if (cosine > 0.0 && !supportInShadow(shape, support, hit.part, X_W)) {
    shading += (1.0 - kAmbientShading) * cosine;
  }
  cv::Vec3b colour;
  for (int c = 0; c < 3; ++c) colour[c] = cv::saturate_cast<uint8_t>(255.0 * shading * albedo[c]);
  return colour;
}

}  // namespace sift_hull
