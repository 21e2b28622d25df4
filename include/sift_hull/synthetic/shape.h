#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

namespace sift_hull {

/// A solid primitive placed in the world by a rotation and a centre.
struct Primitive {
  enum class Type { kSphere, kBox, kTorus };
  Type type = Type::kSphere;
  Eigen::Vector3d centre_W = Eigen::Vector3d::Zero();
  Eigen::Matrix3d R_W_P = Eigen::Matrix3d::Identity();  ///< primitive axes in world coordinates
  /// Sphere: radius in x. Box: half extents. Torus (axis = local z): major radius in x, tube radius
  /// in y.
  Eigen::Vector3d size_m = Eigen::Vector3d::Ones();
  /// A cut: the solid is the union of the other parts with this one taken away (a sphere or a
  /// box only).
  bool subtract = false;

  bool contains(const Eigen::Vector3d& X_W) const;
  /// Radius of a sphere about centre_W holding the primitive.
  double boundingRadius() const;
};

/// Where a ray first enters a solid.
struct RayHit {
  double distance_m = 0.0;                             ///< along the unit ray direction
  Eigen::Vector3d normal_W = Eigen::Vector3d::Zero();  ///< outward unit normal at the hit
};

/// A union of primitives with cuts (parts that take away), the objects of the synthetic scenes.
class Shape {
 public:
  Shape() = default;
  explicit Shape(std::vector<Primitive> parts);

  /// Names accepted by byName(): sphere, box, torus, sculpture (default: a non-convex union of a
  /// box, a sphere and a torus), dumbbell (two spheres joined by a box), and the concave ones a
  /// visual hull cannot recover: cup (a box with a deep square pocket open at the top) and
  /// ublock (a long block with a narrow, deep groove along it, open at the top and at both ends).
  static std::vector<std::string> names();
  static std::string defaultName() { return "sculpture"; }
  /// Throws std::invalid_argument for an unknown name.
  static Shape byName(const std::string& name);
  /// Whether a part takes volume away (silhouettes then do not bound the solid tightly).
  bool hasCuts() const;
  /// The shape with its cuts filled: the parts that add. Its difference with the shape is the
  /// cavities.
  Shape withoutCuts() const;

  const std::vector<Primitive>& parts() const { return parts_; }
  bool contains(const Eigen::Vector3d& X_W) const;
  /// First entry of the ray origin + s * direction (s > 0, direction of unit length) into the
  /// solid; false when it misses. The origin must lie outside the solid.
  bool firstHit(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction, RayHit* hit) const;
  /// A sphere holding the whole shape (its parts that add).
  const Eigen::Vector3d& boundingCentre() const { return bounding_centre_; }
  double boundingRadius() const { return bounding_radius_; }
  /// Tight axis-aligned box of the whole shape.
  void boundingBox(Eigen::Vector3d* min_W, Eigen::Vector3d* max_W) const;

 private:
  bool firstHitWithCuts(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                        RayHit* hit) const;

  std::vector<Primitive> parts_;
  Eigen::Vector3d bounding_centre_ = Eigen::Vector3d::Zero();
  double bounding_radius_ = 0.0;
};

}  // namespace sift_hull
