#include "sift_hull/synthetic/shape.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace sift_hull {
namespace {

struct LocalRay {
  Eigen::Vector3d origin;
  Eigen::Vector3d direction;  // unit length: rotations keep lengths
};

LocalRay toLocal(const Primitive& p, const Eigen::Vector3d& origin, const Eigen::Vector3d& dir) {
  return {p.R_W_P.transpose() * (origin - p.centre_W), p.R_W_P.transpose() * dir};
}

/// Entry and exit distances of a ray through a sphere about the local origin.
bool sphereInterval(const LocalRay& ray, double radius, double* enter, double* leave) {
  const double b = ray.origin.dot(ray.direction);
  const double c = ray.origin.squaredNorm() - radius * radius;
  const double discriminant = b * b - c;
  if (discriminant < 0.0) return false;
  const double root = std::sqrt(discriminant);
  *enter = -b - root;
  *leave = -b + root;
  return *leave > 0.0;
}

bool hitSphere(const LocalRay& ray, double radius, double* distance, Eigen::Vector3d* normal) {
  double enter, leave;
  if (!sphereInterval(ray, radius, &enter, &leave) || enter <= 0.0) return false;
  *distance = enter;
  *normal = (ray.origin + enter * ray.direction) / radius;
  return true;
}

bool hitBox(const LocalRay& ray, const Eigen::Vector3d& half, double* distance,
            Eigen::Vector3d* normal) {
  double enter = -std::numeric_limits<double>::infinity();
  double leave = std::numeric_limits<double>::infinity();
  int enter_axis = 0;
  for (int axis = 0; axis < 3; ++axis) {
    const double inverse = 1.0 / ray.direction[axis];  // +-inf for a parallel ray is intended
    double near = (-half[axis] - ray.origin[axis]) * inverse;
    double far = (half[axis] - ray.origin[axis]) * inverse;
    if (near > far) std::swap(near, far);
    if (std::isnan(near)) return false;  // parallel ray on a slab face
    if (near > enter) {
      enter = near;
      enter_axis = axis;
    }
    leave = std::min(leave, far);
  }
  if (enter > leave || enter <= 0.0) return false;
  *distance = enter;
  *normal = Eigen::Vector3d::Zero();
  (*normal)[enter_axis] = ray.direction[enter_axis] > 0.0 ? -1.0 : 1.0;
  return true;
}

double torusDistance(const Eigen::Vector3d& p, double major, double minor) {
  const double radial = std::hypot(p.x(), p.y()) - major;
  return std::hypot(radial, p.z()) - minor;
}

/// Sphere tracing on the torus' exact distance function, inside its bounding sphere.
bool hitTorus(const LocalRay& ray, double major, double minor, double* distance,
              Eigen::Vector3d* normal) {
  double enter, leave;
  if (!sphereInterval(ray, major + minor, &enter, &leave)) return false;
  const double tolerance = 1e-7 * (major + minor);
  double s = std::max(enter, 0.0);
  for (int step = 0; step < 400 && s <= leave; ++step) {
    const Eigen::Vector3d p = ray.origin + s * ray.direction;
    const double d = torusDistance(p, major, minor);
    if (d < tolerance) {
      *distance = s;
      const Eigen::Vector3d core = major * Eigen::Vector3d(p.x(), p.y(), 0.0).normalized();
      *normal = (p - core).normalized();
      return true;
    }
    s += d;
  }
  return false;
}

/// Where a ray is inside a sphere or a box: [enter, leave] with the outward normals there (world
/// frame); false when it misses.
bool primitiveInterval(const Primitive& part, const Eigen::Vector3d& origin,
                       const Eigen::Vector3d& direction, double* enter, double* leave,
                       Eigen::Vector3d* enter_normal_W, Eigen::Vector3d* leave_normal_W) {
  const LocalRay ray = toLocal(part, origin, direction);
  if (part.type == Primitive::Type::kSphere) {
    if (!sphereInterval(ray, part.size_m.x(), enter, leave)) return false;
    *enter_normal_W = part.R_W_P * (ray.origin + *enter * ray.direction) / part.size_m.x();
    *leave_normal_W = part.R_W_P * (ray.origin + *leave * ray.direction) / part.size_m.x();
    return true;
  }
  *enter = -std::numeric_limits<double>::infinity();
  *leave = std::numeric_limits<double>::infinity();
  int enter_axis = 0, leave_axis = 0;
  for (int axis = 0; axis < 3; ++axis) {
    const double inverse = 1.0 / ray.direction[axis];
    double near = (-part.size_m[axis] - ray.origin[axis]) * inverse;
    double far = (part.size_m[axis] - ray.origin[axis]) * inverse;
    if (near > far) std::swap(near, far);
    if (std::isnan(near)) return false;
    if (near > *enter) *enter = near, enter_axis = axis;
    if (far < *leave) *leave = far, leave_axis = axis;
  }
  if (*enter > *leave || *leave <= 0.0) return false;
  Eigen::Vector3d n_in = Eigen::Vector3d::Zero(), n_out = Eigen::Vector3d::Zero();
  n_in[enter_axis] = ray.direction[enter_axis] > 0.0 ? -1.0 : 1.0;
  n_out[leave_axis] = ray.direction[leave_axis] > 0.0 ? 1.0 : -1.0;
  *enter_normal_W = part.R_W_P * n_in;
  *leave_normal_W = part.R_W_P * n_out;
  return true;
}

bool hitPrimitive(const Primitive& part, const Eigen::Vector3d& origin,
                  const Eigen::Vector3d& direction, RayHit* hit) {
  const LocalRay ray = toLocal(part, origin, direction);
  Eigen::Vector3d normal_P;
  bool found = false;
  switch (part.type) {
    case Primitive::Type::kSphere:
      found = hitSphere(ray, part.size_m.x(), &hit->distance_m, &normal_P);
      break;
    case Primitive::Type::kBox:
      found = hitBox(ray, part.size_m, &hit->distance_m, &normal_P);
      break;
    case Primitive::Type::kTorus:
      found = hitTorus(ray, part.size_m.x(), part.size_m.y(), &hit->distance_m, &normal_P);
      break;
  }
  if (found) hit->normal_W = part.R_W_P * normal_P;
  return found;
}

/// Half extents, along the world axes, of a primitive's tight axis-aligned box.
Eigen::Vector3d halfExtents(const Primitive& p) {
  switch (p.type) {
    case Primitive::Type::kSphere:
      return Eigen::Vector3d::Constant(p.size_m.x());
    case Primitive::Type::kBox:
      return p.R_W_P.cwiseAbs() * p.size_m;
    case Primitive::Type::kTorus: {
      const Eigen::Vector3d axis = p.R_W_P.col(2);
      const Eigen::Vector3d in_plane = (1.0 - axis.array().square()).max(0.0).sqrt();
      return p.size_m.x() * in_plane + Eigen::Vector3d::Constant(p.size_m.y());
    }
  }
  return Eigen::Vector3d::Zero();
}

/// An upper bound, exact for spheres and boxes, of the distance from X_W to the primitive's points.
double farthestDistance(const Primitive& p, const Eigen::Vector3d& X_W) {
  if (p.type != Primitive::Type::kBox) return (p.centre_W - X_W).norm() + p.boundingRadius();
  double farthest = 0.0;
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3d sign(corner & 1 ? 1 : -1, corner & 2 ? 1 : -1, corner & 4 ? 1 : -1);
    const Eigen::Vector3d corner_W = p.centre_W + p.R_W_P * sign.cwiseProduct(p.size_m);
    farthest = std::max(farthest, (corner_W - X_W).norm());
  }
  return farthest;
}

Primitive makePrimitive(Primitive::Type type, const Eigen::Vector3d& centre,
                        const Eigen::Vector3d& size_m,
                        const Eigen::Matrix3d& R = Eigen::Matrix3d::Identity()) {
  Primitive p;
  p.type = type;
  p.centre_W = centre;
  p.size_m = size_m;
  p.R_W_P = R;
  return p;
}

Eigen::Matrix3d rotation(double angle_rad, const Eigen::Vector3d& axis) {
  return Eigen::AngleAxisd(angle_rad, axis.normalized()).toRotationMatrix();
}

}  // namespace

bool Primitive::contains(const Eigen::Vector3d& X_W) const {
  const Eigen::Vector3d p = R_W_P.transpose() * (X_W - centre_W);
  switch (type) {
    case Type::kSphere:
      return p.squaredNorm() < size_m.x() * size_m.x();
    case Type::kBox:
      return (p.cwiseAbs().array() < size_m.array()).all();
    case Type::kTorus:
      return torusDistance(p, size_m.x(), size_m.y()) < 0.0;
  }
  return false;
}

double Primitive::boundingRadius() const {
  switch (type) {
    case Type::kSphere:
      return size_m.x();
    case Type::kBox:
      return size_m.norm();
    case Type::kTorus:
      return size_m.x() + size_m.y();
  }
  return 0.0;
}

Shape::Shape(std::vector<Primitive> parts) : parts_(std::move(parts)) {
  const bool adds = std::any_of(parts_.begin(), parts_.end(), [](auto& p) { return !p.subtract; });
  if (!adds) throw std::invalid_argument("a shape needs at least one primitive that adds");
  for (const Primitive& p : parts_) {
    if (hasCuts() && p.type == Primitive::Type::kTorus) {
      throw std::invalid_argument("a shape with cuts takes spheres and boxes only");
    }
  }
  Eigen::Vector3d lo, hi;
  boundingBox(&lo, &hi);
  bounding_centre_ = 0.5 * (lo + hi);
  for (const Primitive& p : parts_) {
    if (p.subtract) continue;
    bounding_radius_ = std::max(bounding_radius_, farthestDistance(p, bounding_centre_));
  }
}

Shape Shape::withoutCuts() const {
  std::vector<Primitive> adding;
  for (const Primitive& p : parts_) {
    if (!p.subtract) adding.push_back(p);
  }
  return Shape(std::move(adding));
}

bool Shape::hasCuts() const {
  return std::any_of(parts_.begin(), parts_.end(), [](const Primitive& p) { return p.subtract; });
}

std::vector<std::string> Shape::names() {
  return {"sculpture", "sphere", "box", "torus", "dumbbell", "cup", "ublock", "bowl"};
}

Shape Shape::byName(const std::string& name) {
  using T = Primitive::Type;
  const Eigen::Vector3d x = Eigen::Vector3d::UnitX(), y = Eigen::Vector3d::UnitY();
  if (name == "sphere") return Shape({makePrimitive(T::kSphere, {0, 0, 0}, {0.8, 0, 0})});
  if (name == "box") {
    return Shape({makePrimitive(T::kBox, {0, 0, 0}, {0.7, 0.5, 0.4}, rotation(0.4, {1, 2, 3}))});
  }
  if (name == "torus") {
    return Shape({makePrimitive(T::kTorus, {0, 0, 0}, {0.7, 0.25, 0}, rotation(0.5, x))});
  }
  if (name == "dumbbell") {
    return Shape({makePrimitive(T::kSphere, {-0.6, 0, 0}, {0.4, 0, 0}),
                  makePrimitive(T::kSphere, {0.6, 0, 0}, {0.4, 0, 0}),
                  makePrimitive(T::kBox, {0, 0, 0}, {0.6, 0.12, 0.12})});
  }
  if (name == "sculpture") {
    return Shape({makePrimitive(T::kBox, {0, 0, -0.55}, {0.6, 0.45, 0.2}, rotation(0.3, {0, 0, 1})),
                  makePrimitive(T::kSphere, {0.05, 0, 0.05}, {0.42, 0, 0}),
                  makePrimitive(T::kTorus, {0.05, 0, 0.2}, {0.5, 0.14, 0}, rotation(1.3, y))});
  }
  if (name == "cup") {  // walls 0.2 m, floor 0.3 m, a pocket 1.0 m wide and 0.9 m deep
    Primitive pocket = makePrimitive(T::kBox, {0, 0, 0.2}, {0.5, 0.5, 0.5});
    pocket.subtract = true;
    return Shape({makePrimitive(T::kBox, {0, 0, 0}, {0.7, 0.7, 0.6}), pocket});
  }
  if (name == "ublock") {  // a groove 0.3 m wide and 0.5 m deep along the block's 1.8 m length
    Primitive groove = makePrimitive(T::kBox, {0, 0, 0.25}, {0.15, 1.0, 0.3});
    groove.subtract = true;
    return Shape({makePrimitive(T::kBox, {0, 0, 0}, {0.6, 0.9, 0.45}), groove});
  }
  if (name == "bowl") {  // a round dent 0.35 m deep and 1.09 m across in a block's top face
    Primitive dent = makePrimitive(T::kSphere, {0, 0, 0.65}, {0.6, 0, 0});
    dent.subtract = true;
    return Shape({makePrimitive(T::kBox, {0, 0, 0}, {0.7, 0.7, 0.4}), dent});
  }
  throw std::invalid_argument("unknown shape '" + name + "'");
}

bool Shape::contains(const Eigen::Vector3d& X_W) const {
  bool inside = false;
  for (const Primitive& p : parts_) {
    if (p.subtract && p.contains(X_W)) return false;
    inside = inside || (!p.subtract && p.contains(X_W));
  }
  return inside;
}

bool Shape::firstHit(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                     RayHit* hit) const {
  if (hasCuts()) return firstHitWithCuts(origin, direction, hit);
  // The union's surface is first entered where the first part is entered, the origin being outside.
  bool found = false;
  for (const Primitive& part : parts_) {
    RayHit candidate;
    if (hitPrimitive(part, origin, direction, &candidate) &&
        (!found || candidate.distance_m < hit->distance_m)) {
      *hit = candidate;
      found = true;
    }
  }
  return found;
}

/// The solid is entered where a part that adds is entered or a cut is left, at the first such
/// place whose next point along the ray lies inside the solid.
bool Shape::firstHitWithCuts(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                             RayHit* hit) const {
  std::vector<RayHit> candidates;
  for (const Primitive& part : parts_) {
    double enter, leave;
    Eigen::Vector3d n_enter, n_leave;
    if (!primitiveInterval(part, origin, direction, &enter, &leave, &n_enter, &n_leave)) continue;
    if (!part.subtract && enter > 0.0) candidates.push_back({enter, n_enter});
    if (part.subtract && leave > 0.0) candidates.push_back({leave, -n_leave});
  }
  std::sort(candidates.begin(), candidates.end(),
            [](const RayHit& a, const RayHit& b) { return a.distance_m < b.distance_m; });
  const double step = 1e-9 * std::max(bounding_radius_, 1.0);
  for (const RayHit& candidate : candidates) {
    if (contains(origin + (candidate.distance_m + step) * direction)) {
      *hit = candidate;
      return true;
    }
  }
  return false;
}

void Shape::boundingBox(Eigen::Vector3d* min_W, Eigen::Vector3d* max_W) const {
  *min_W = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  *max_W = -*min_W;
  for (const Primitive& p : parts_) {
    if (p.subtract) continue;
    const Eigen::Vector3d half = halfExtents(p);
    *min_W = min_W->cwiseMin(p.centre_W - half);
    *max_W = max_W->cwiseMax(p.centre_W + half);
  }
}

}  // namespace sift_hull
