#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "sift_hull/geometry/camera.h"

namespace sift_hull {

/// Where the views' optical axes come closest to meeting (least squares over the axes).
struct CommonPoint {
  Eigen::Vector3d point_W = Eigen::Vector3d::Zero();
  /// Largest distance of the point from an optical axis, in world units (metres for scenes).
  double max_axis_distance_m = 0.0;
  bool in_front_of_all = false;  ///< the point has positive depth in every view
  bool well_defined = false;     ///< the axes are not all parallel (needs two views or more)
  int first_behind = -1;         ///< index of the first camera the point is behind, -1 if none
};

/// The point nearest to all the cameras' optical axes (least squares), with how far it is from the
/// farthest axis and whether it lies in front of every camera; not well defined when the axes are
/// all parallel or there are fewer than two cameras.
CommonPoint opticalAxesMeetingPoint(const std::vector<PinholeCamera>& cameras);

/// What orientCameras did.
struct CameraOrientation {
  std::vector<size_t> negated;  ///< views whose P's sign was flipped
  bool mirrored_world = false;  ///< every camera is improper: the world frame is left-handed
  bool by_scene_point = false;  ///< a scene point decided (false: too few views, signs kept)
};

/// Chooses the sign of each view's projection matrix from the data (cheirality): the scene point is
/// where the optical axes meet (opticalAxesMeetingPoint: the axes are lines, the same for P and
/// -P), and each view whose P puts that point behind the camera is negated (negated()), so that
/// the scene has positive depth in every view. With fewer than two views or parallel axes there is
/// no such point and the signs are kept (det R = +1, a right-handed world). Afterwards every camera
/// must have the same handedness, all proper or all improper (a mirrored world): one world frame
/// cannot be both. Throws std::invalid_argument naming the views of the smaller group (`names`,
/// optional, name the views) otherwise: no choice of signs puts the scene in front of them in the
/// world frame of the others.
CameraOrientation orientCameras(std::vector<PinholeCamera>* cameras,
                                const std::vector<std::string>& names = {});

/// The cameras' mutual distance: the largest distance between two camera centres, in world units;
/// 0 for fewer than two cameras.
double camerasMutualDistance(const std::vector<PinholeCamera>& cameras);

/// How far one camera may stray from the others: a centre more than this many times the cameras'
/// median distance from their median centre (per axis) is a translation off by orders of
/// magnitude, and would set the scale of everything computed from the cameras together.
constexpr double kMaxCameraSpread = 1e6;

/// Throws std::invalid_argument naming the view (`names`, optional) whose camera centre lies more
/// than kMaxCameraSpread times the cameras' median distance from their median centre, or at a
/// distance that is not finite. Needs three cameras or more (with two, neither is the odd one).
void requireNoStrayCamera(const std::vector<PinholeCamera>& cameras,
                          const std::vector<std::string>& names = {});

}  // namespace sift_hull
