#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "sift_hull/geometry/camera.h"
#include "sift_hull/hull/bounding_box.h"
#include "sift_hull/hull/silhouette.h"

namespace sift_hull {

/// Silhouettes from the photographs of a calibrated set, without masks (the "views" method of
/// SilhouetteConfig). The cameras tell where the object is: what they all look at.
///  1. Prior: the largest ball inside the intersection of all views' frusta (its centre found on a
///     grid, refined twice, inside the frusta's LP box; hullBoundingBox), projected into each view
///     as "probably object". It needs no metric camera and no point on the optical axes.
///  2. Each view segmented by OpenCV's GrabCut at half the working size, its border band certain
///     background (so that floor, table and turntable colours enter the background model).
///  3. A coarse hull carved from those masks on a grid of `kCoarseCells` cells along the longest
///     side, tolerating the disagreement of a tenth of the views; a support below the object (a
///     floor patch, a shadow, a turntable disc: a flat layer at the bottom, along the cameras' mean
///     up direction, much wider than what stands on it) is cut away.
///  4. The support plane, when the views agree on one around the object: a sweep along up over
///     the lower half of the coarse hull for the height at which the most pixels outside the
///     first masks match their nearest view through the plane's homography (7x7 NCC > 0.8).
///  5. The hull projected back as the new prior; each view segmented again at the working size,
///     what matches 4 neighbouring views through the support plane (floor, turntable, the
///     object's shadow on them) certain background; the mask is that segmentation inside the
///     hull's projection, upsampled to the image.
struct ViewSilhouettes {
  std::vector<cv::Mat> masks;             ///< CV_8UC1 at each image's full size, 255 inside
  std::vector<cv::Mat> priors;            ///< working size: the ball's projection, 255 inside
  std::vector<cv::Mat> hull_projections;  ///< working size: the coarse hull's projection
  std::optional<Eigen::Vector3d> ball_centre_W;
  double ball_radius = 0.0;
  /// The support cut from the coarse hull: its share of the coarse hull's cells, and its top's
  /// height above the hull's lowest cell along the up direction (world units). 0 when none.
  double support_fraction = 0.0;
  double support_height = 0.0;
  Eigen::Vector3d up_W = Eigen::Vector3d::UnitZ();
  /// The plane the object stands on, when the views agree on one (height along up_W, world
  /// units), and the share of the probed pixels around the object that agree there.
  std::optional<double> support_plane_height;
  double support_plane_share = 0.0;
  /// silhouetteAgreement() of the masks.
  double agreement = 0.0;
  /// The "auto" method: the one whose silhouettes were used ("views" or "background"), and the
  /// background method's agreement; negative when it was not a candidate (a textured border in
  /// some view, which only GrabCut separates: `background_reason` says which).
  std::string method = "views";
  double background_agreement = -1.0;
  std::string background_reason;
  /// Views whose segmentation the other views do not confirm, named for the user.
  std::vector<std::string> warnings;
  double time_ms = 0.0;
};

/// Cells along the longest side of the coarse hull's grid.
inline constexpr int kCoarseCells = 96;

/// The views' silhouettes by the method above. `images` are BGR, 8 bits, at the working size
/// (SilhouetteConfig::segment_side_px on the longest side, or smaller), `full_size` the size of the
/// images the cameras are for. Throws std::runtime_error, naming the views, when the set cannot be
/// separated: fewer than two views, frusta with no common part, or a coarse hull that is empty.
ViewSilhouettes silhouettesFromViews(const std::vector<cv::Mat>& images,
                                     const std::vector<PinholeCamera>& cameras,
                                     const std::vector<std::string>& names, cv::Size full_size,
                                     const SilhouetteConfig& config);

/// How well silhouettes agree across views, on [0, 1]: the mean IoU of each view's mask (at the
/// working size of `segment_side_px`) with the projection of the coarse hull carved from all the
/// masks inside the frusta's box, no view's disagreement tolerated. Silhouettes that take a part
/// of the background in some views but not in others, or lose a part of the object, agree less.
/// Throws std::invalid_argument for fewer than two masks or masks of different sizes, and
/// std::runtime_error for frusta with no common part.
double silhouetteAgreement(const std::vector<cv::Mat>& masks,
                           const std::vector<PinholeCamera>& cameras,
                           const std::vector<std::string>& names, int segment_side_px);

/// The "auto" method's choice between the views method's silhouettes (`found`, with its
/// agreement) and the background method's (`plain`, one per view at full size, empty where a
/// view's border is textured or the view carries its own alpha mask). The background method's,
/// a colour model at full resolution, where every view has one and they agree across the views as
/// well (silhouetteAgreement) to within the measure's resolution (0.01); the views method's where
/// they agree clearly better. Sets found->method, background_agreement or background_reason, and
/// on the background method's side its masks (the views method's warnings cleared).
void chooseBackgroundWhereItAgrees(ViewSilhouettes* found, std::vector<cv::Mat> plain,
                                   const std::vector<std::string>& names,
                                   const std::vector<PinholeCamera>& cameras,
                                   const SilhouetteConfig& config);

/// The working size of an image of `full_size`: its longest side brought to at most
/// `segment_side_px`, the aspect kept.
cv::Size workingSize(cv::Size full_size, int segment_side_px);

/// The centre and radius of (about) the largest ball inside every camera's frustum, inside `box`;
/// nullopt when no point of the box is inside every frustum.
std::optional<std::pair<Eigen::Vector3d, double>> largestBallInFrusta(
    const std::vector<PinholeCamera>& cameras, cv::Size full_size, const Box3d& box);

}  // namespace sift_hull
