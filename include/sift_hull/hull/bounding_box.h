#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "sift_hull/geometry/camera.h"

namespace sift_hull {

/// An axis-aligned box in world coordinates.
struct Box3d {
  Eigen::Vector3d min_W = Eigen::Vector3d::Zero();
  Eigen::Vector3d max_W = Eigen::Vector3d::Zero();

  Eigen::Vector3d size() const { return max_W - min_W; }
  Eigen::Vector3d centre() const { return 0.5 * (min_W + max_W); }
  bool contains(const Eigen::Vector3d& X_W, double tolerance_m = 0.0) const;
};

/// The 2-D bounds of a silhouette in pixel coordinates (pixel centres at integers), enclosing whole
/// pixels: from the leftmost inside pixel's u - 0.5 to the rightmost's u + 0.5, likewise in v. A
/// side is unbounded (`has_*` false) when the silhouette touches the image border on that side and
/// the border does not bound the object (the object may go on outside the image).
struct SilhouetteBounds {
  bool empty = true;  ///< no pixel inside
  double u_min_px = 0.0, u_max_px = 0.0, v_min_px = 0.0, v_max_px = 0.0;
  bool has_u_min = false, has_u_max = false, has_v_min = false, has_v_max = false;

  int boundedSides() const { return has_u_min + has_u_max + has_v_min + has_v_max; }
};

/// The views that see the box behind them: the box's centre has depth <= 0 (cheirality), by name
/// (`names`, optional, same length; else "view <i>"). A box that every view sees behind it holds
/// nothing a silhouette shows.
std::vector<std::string> viewsSeeingBoxBehind(const Box3d& box,
                                              const std::vector<PinholeCamera>& cameras,
                                              const std::vector<std::string>& names = {});

/// Bounds of a CV_8UC1 mask (non-zero inside). `border_bounds_object`: a silhouette side on the
/// image border still bounds the object (true when views that see a point outside the image carve
/// it). Throws std::invalid_argument for an empty Mat or another type.
SilhouetteBounds silhouetteBounds(const cv::Mat& mask, bool border_bounds_object);

/// The bounds of a silhouette whose inside pixels span the rectangle `inside` (empty: none) of an
/// image of `image_size`, as silhouetteBounds gives them.
SilhouetteBounds boundsOfInside(const cv::Rect& inside, cv::Size image_size,
                                bool border_bounds_object);

/// Why no bounding box exists.
class HullBoxError : public std::runtime_error {
 public:
  enum class Reason {
    kTooFewViews,  ///< fewer than two views with a non-empty silhouette and a bounded side
    kEmpty,        ///< the viewing cones do not intersect (or a silhouette is empty)
    kUnbounded,    ///< the cones' intersection is unbounded (rays nearly parallel, sides open)
  };
  HullBoxError(Reason reason, const std::string& message)
      : std::runtime_error(message), reason_(reason) {}
  Reason reason() const { return reason_; }

 private:
  Reason reason_;
};

/// The paper's eq. 8 solved exactly: the smallest axis-aligned box holding every point X whose
/// projection lies inside every view's silhouette bounds. With w = p3 . [X; 1] > 0 the depth,
/// u_min w <= p1 . [X; 1] <= u_max w and v_min w <= p2 . [X; 1] <= v_max w are linear, four per
/// view (fewer for open sides); six linear programs (min and max of x, y, z) are solved by GLPK's
/// simplex. `names` (optional, same length) name views in errors. Throws HullBoxError.
Box3d hullBoundingBox(const std::vector<PinholeCamera>& cameras,
                      const std::vector<SilhouetteBounds>& bounds,
                      const std::vector<std::string>& names = {});

}  // namespace sift_hull
