#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "sift_hull/geometry/camera.h"
#include "sift_hull/hull/bounding_box.h"
#include "sift_hull/hull/distance_map.h"
#include "sift_hull/hull/hull_config.h"
#include "sift_hull/hull/run_length_mask.h"

namespace sift_hull {

namespace detail {
struct DistanceKernel;
}  // namespace detail

/// Where a view puts a cell or point.
enum class Verdict : uint8_t { kOut, kIn, kUndecided };

/// Points in structure-of-arrays form, for batched look-ups: coordinates as floats in the view's
/// local frame (HullView::useFrame), X_local = (X_W - origin_W) / scale.
struct PointBatch {
  const float* x;
  const float* y;
  const float* z;
  size_t count;
};

/// One calibrated silhouette, ready for carving. With a distorted camera the distance map is
/// resampled onto ideal pixels (SignedDistanceMap::undistorted) and the bounds are those of the
/// undistorted silhouette (viewBounds), so that carving and the LP use the ideal pinhole.
class HullView {
 public:
  /// Throws std::invalid_argument for a mask that is not a non-empty CV_8UC1, or a camera whose
  /// lens distortion folds over within the image (naming the view).
  HullView(std::string name, const PinholeCamera& camera, const cv::Mat& mask,
           const HullConfig& config);
  /// A view whose distance map is sampled every `distance_reduction` pixels
  /// (reducedSignedDistanceMap(); 1: full resolution, as the constructor above), its error bound
  /// added to the slack of the ball verdicts. Throws std::invalid_argument for an empty mask or a
  /// reduction outside [1, kMaxDistanceReduction].
  HullView(std::string name, const PinholeCamera& camera, RunLengthMask mask,
           const HullConfig& config, int distance_reduction);
  HullView(const HullView& other);
  HullView& operator=(const HullView& other);
  HullView(HullView&& other) noexcept;
  HullView& operator=(HullView&& other) noexcept;
  ~HullView();

  const std::string& name() const { return name_; }
  const PinholeCamera& camera() const { return camera_; }
  /// The silhouette at full resolution, decoded from its run-length form (a new image per call).
  cv::Mat mask() const { return mask_.decode(); }
  /// The silhouette as the view holds it.
  const RunLengthMask& runLengthMask() const { return mask_; }
  /// Image pixels per side of one element of the distance map (1: full resolution).
  int distanceReduction() const { return distance_.reduction(); }
  /// The distance map's error bound, added to the slack (SignedDistanceMap::errorBound_px()).
  float distanceErrorBound_px() const { return distance_.errorBound_px(); }
  /// The silhouette's 2-D bounds in ideal pixels (viewBounds); open sides where the border cuts
  /// it, unless carving outside.
  const SilhouetteBounds& bounds() const { return bounds_; }
  cv::Size imageSize() const { return mask_.size(); }

  /// D_i(P_i X) of the paper's eq. 9 in pixels. A point not in front of the camera gets
  /// kFarOutside_px when the view has a bounded side (the LP's depth row), else -kFarOutside_px.
  float valueAt(const Eigen::Vector3d& X_W) const;
  /// The brute-force test of dense carving: whether the view keeps a point, by the mask pixel
  /// nearest to its projection, or by the bounds outside the image.
  bool keeps(const Eigen::Vector3d& X_W) const;
  /// values[i] = max(values[i], D_i(P_i X_i)) for a batch of points in the local frame: f_iso
  /// built view by view.
  void maxInto(const PointBatch& points, float* values) const;
  /// For balls of one radius (local units) around up to 32 centres (local frame), from the distance
  /// at each centre and the ball's projected radius (plus the slack): maxInto for the centres; bit
  /// i of `out_bits` set when the view sees all of ball i outside the silhouette, of `in_bits` when
  /// all inside.
  void classifyBalls(const PointBatch& centres, float radius_m, float* values, uint32_t* out_bits,
                     uint32_t* in_bits) const;

  /// The distance at a centre (local frame) and `reach`, the most it can change within
  /// `radius` (local units) of it: the ball's projected radius plus the slack, the bound
  /// classifyBalls uses; infinite when the ball reaches the camera's plane.
  void ballBound(float x, float y, float z, float radius, float* value, float* reach) const;

  static constexpr float kFarOutside_px = 1e6f;

  /// The frame of the batched look-ups: X_local = (X_W - origin_W) / scale. Single-precision
  /// arithmetic keeps its relative precision in a frame around the hull whatever the world
  /// coordinates are (a map frame far from its origin, millimetres or kilometres). Projection is
  /// invariant to the scale, so only the camera's translation changes: (R origin_W + t) / scale.
  /// Throws std::invalid_argument when the camera lies more than kMaxCameraDistance local units
  /// from the origin (it would see the frame's unit cube as less than a millionth of its focal
  /// length) or the frame is not finite and positive. The default frame is the world's.
  void useFrame(const Eigen::Vector3d& origin_W, double scale);
  static constexpr double kMaxCameraDistance = 1e6;

 private:
  /// Pixel of a point in the camera frame (K's last row is 0 0 1).
  Eigen::Vector2d pixelOf(const Eigen::Vector3d& X_C) const;

  detail::DistanceKernel makeKernel(const HullConfig& config) const;

  std::string name_;
  PinholeCamera camera_;
  RunLengthMask mask_;
  SilhouetteBounds bounds_;
  SignedDistanceMap distance_;
  bool carves_behind_ = true;
  Eigen::Vector3d frame_origin_W_ = Eigen::Vector3d::Zero();
  double frame_scale_ = 1.0;
  /// What the batched look-ups read (src/core/hull/distance_kernel.h); copied with the view.
  std::unique_ptr<detail::DistanceKernel> kernel_;
};

/// Prepares views (their distance transforms) on `config.threads` threads. Names, cameras and
/// masks have one entry per view.
std::vector<HullView> makeHullViews(const std::vector<std::string>& names,
                                    const std::vector<PinholeCamera>& cameras,
                                    const std::vector<cv::Mat>& masks, const HullConfig& config);

/// The bounds of a view's silhouette in the ideal pixels of its camera, as HullView::bounds()
/// gives them and the box LP takes them: the mask's bounds, or for a camera with lens distortion
/// those of the undistorted silhouette (its outline's pixel corners undistorted; open sides kept).
/// Throws std::invalid_argument naming the view when its distortion folds over within its image.
SilhouetteBounds viewBounds(const std::string& name, const PinholeCamera& camera,
                            const RunLengthMask& mask, const HullConfig& config);

}  // namespace sift_hull
