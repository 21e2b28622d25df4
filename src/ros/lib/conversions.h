#pragma once

// Every conversion between sift_hull's core types and ROS messages.

#include <geometry_msgs/Point.h>
#include <geometry_msgs/TransformStamped.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud2.h>
#include <visualization_msgs/Marker.h>
#include <visualization_msgs/MarkerArray.h>

#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <limits>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "sift_hull/Correspondences.h"
#include "sift_hull/Keypoint.h"
#include "sift_hull/Octomap.h"
#include "sift_hull/SurfacePoints.h"
#include "sift_hull/features/matching.h"
#include "sift_hull/filters/filter.h"
#include "sift_hull/geometry/camera.h"
#include "sift_hull/hull/bounding_box.h"
#include "sift_hull/hull/hull_octomap.h"
#include "sift_hull/hull/mesh.h"
#include "sift_hull/refine/surface_points.h"

namespace octomap {
class ColorOcTree;
class OcTree;
}  // namespace octomap

namespace sift_hull {
namespace ros_conversions {

/// Whether the message's data holds its width x height pixels of `bytes_per_pixel` bytes, all
/// sizes in size_t before any pointer arithmetic: false, with `why_not`, for an empty image, a
/// side over limits::kMaxImageSidePx, more than limits::kMaxDecodedImagePixels pixels, a step
/// shorter than a row, or data shorter than
/// step x height (a height x step that would wrap in 32 bits is caught).
bool holdsPixels(const sensor_msgs::Image& image, size_t bytes_per_pixel, std::string* why_not);

/// Whether the image has at most `max_pixels` pixels (SiftConfig::max_image_pixels); false, with
/// `why_not`, otherwise. Reads only the header fields.
bool withinPixelLimit(const sensor_msgs::Image& image, size_t max_pixels, std::string* why_not);

/// A silhouette message as a CV_8UC1 mask sharing nothing with the message. Accepts mono8 and
/// 8UC1 (cv_bridge's encoding of a uint8 array; the same bytes), non-zero inside; returns an empty
/// Mat and sets `why_not` for another encoding or pixels the data does not hold (holdsPixels).
cv::Mat maskFromImage(const sensor_msgs::Image& image, std::string* why_not);

/// Whether eightBitImage takes the image: an 8-bit colour or mono encoding whose pixels the data
/// holds (holdsPixels); false, with `why_not`, otherwise. Reads the header and sizes only.
bool holdsEightBitImage(const sensor_msgs::Image& image, std::string* why_not);

/// An 8-bit colour or mono image as BGR or grey, sharing the message's pixels (keep the message
/// while the Mat is in use). Returns an empty Mat and sets `why_not` for another encoding or
/// pixels the data does not hold (holdsPixels).
cv::Mat eightBitImage(const sensor_msgs::ImageConstPtr& image, std::string* why_not);

/// The silhouette an 8-bit image with an alpha channel (rgba8, bgra8) holds: alpha at least 128,
/// CV_8UC1 with 255 inside. Empty for another encoding or an alpha that is constant.
cv::Mat alphaMask(const sensor_msgs::ImageConstPtr& image);

/// What a camera_info says of its image, read through image_geometry::PinholeCameraModel.
struct CameraInfoGeometry {
  /// The image is rectified: its camera is P's K' (and R), not K and D.
  bool rectified = false;
  /// The camera matrix of the image as it is (pixels): K for a raw image, K' = P[:3, :3] for a
  /// rectified one.
  Eigen::Matrix3d K = Eigen::Matrix3d::Identity();
  LensDistortion distortion;  ///< D of a raw image; zero for a rectified one
  Eigen::Matrix3d K_rect = Eigen::Matrix3d::Identity();  ///< P[:3, :3] (K when P is all zero)
  /// R: the rotation from the camera's frame (frame_id) into the rectified frame (I when all zero).
  Eigen::Matrix3d R_rect_C = Eigen::Matrix3d::Identity();
  /// P's fourth column in metres, K'^-1 P[:, 3]: the camera's origin in the rectified frame of the
  /// pair's first camera; (-B, 0, 0) for the right camera of a horizontal pair of baseline B m
  /// (P[0,3] = -fx' B).
  Eigen::Vector3d t_rect_m = Eigen::Vector3d::Zero();
};

/// Which matrices of `info` describe its image. Raw (the default): K and D (plumb_bob with 5
/// coefficients, rational_polynomial with 8, equidistant, OpenCV's fisheye, with 4), R and P only
/// kept for stereo. Rectified when `rectified` is set (image_proc's image_rect: its camera_info is
/// the raw image's, D included) or when D is all zero (or empty) and R is not I or P[:3, :3] is not
/// K: then the camera is K' = P[:3, :3] looking along R. An all-zero R or P counts as I or K [I |
/// 0]. Returns false and sets `why_not` for a K or P that is zero, not finite or not upper
/// triangular with positive focal lengths, a P with Tz (P[11]) not 0, an R that is not a rotation,
/// another distortion model or a non-finite coefficient, binning or a region of interest.
bool cameraInfoGeometry(const sensor_msgs::CameraInfo& info, bool rectified,
                        CameraInfoGeometry* geometry, std::string* why_not);

/// The camera of a view: cameraInfoGeometry's K and D (raw), or K' and R (rectified: the camera
/// frame turned by R), and the pose T_W_C of the camera's frame (frame_id) in the world frame, as
/// tf gives it. P's fourth column is not used: tf places the camera. Returns false and sets
/// `why_not` as cameraInfoGeometry does, for a pose that is not finite, or an image size that
/// disagrees with `image_size` (when non-zero).
bool cameraFromInfo(const sensor_msgs::CameraInfo& info, const Eigen::Isometry3d& T_W_C,
                    cv::Size image_size, PinholeCamera* camera, std::string* why_not,
                    bool rectified = false);

/// The cameras of a stereo pair whose camera_infos share one frame_id (stereo_image_proc's
/// convention), in that frame: tf knows one frame only, and the baseline is in the right P,
/// P[0,3] = -fx' B (and P[1,3] = -fy' B_y). The pair's rectified frame is the left R applied to
/// the shared frame; each camera sits at K'^-1 P[:, 3] in it (the right one at (B, B_y, 0) m), a
/// rectified image's camera looking along that frame, a raw one's turned back by its own R (with
/// its own K and D). Fails, with `why_not`, as cameraFromInfo does for either camera_info.
bool sharedFrameStereo(const sensor_msgs::CameraInfo& left_info,
                       const sensor_msgs::CameraInfo& right_info, cv::Size left_size,
                       cv::Size right_size, bool rectified, PinholeCamera* left,
                       PinholeCamera* right, std::string* why_not);

/// An 8-bit image as a message: CV_8UC1 as mono8, CV_8UC3 as bgr8. Throws std::invalid_argument
/// for another type.
sensor_msgs::Image imageMessage(const cv::Mat& image, const std_msgs::Header& header);

/// camera_info of a camera of the given image size: K, P = K [I | 0], R = I, and its lens
/// distortion as plumb_bob (k1, k2, p1, p2, k3; zero for an ideal lens), as rational_polynomial
/// (8 coefficients) when k4, k5 or k6 is not zero, or as equidistant (k1..k4) for a fisheye lens.
sensor_msgs::CameraInfo cameraInfoMessage(const PinholeCamera& camera, cv::Size size,
                                          const std_msgs::Header& header);

/// The camera's pose T_W_C: the transform from `world_frame` to `camera_frame` that tf needs.
/// Throws std::invalid_argument for an improper camera (a mirrored world frame, det R = -1),
/// which no rotation describes.
geometry_msgs::TransformStamped cameraPoseMessage(const PinholeCamera& camera,
                                                  const std::string& world_frame,
                                                  const std::string& camera_frame,
                                                  const ros::Time& stamp);

/// The tree as an Octomap message (binary stream, as octomap_msgs::binaryMapToMsg writes it):
/// binary true, id "OcTree", resolution in metres, data holding occupied / free per leaf only.
sift_hull::Octomap octomapMessage(const octomap::OcTree& tree, const std_msgs::Header& header);
/// The same message from compactOctomap's map (its binary_data, the same bytes).
sift_hull::Octomap octomapMessage(const CompactOctomap& map, const std_msgs::Header& header);

/// The tree as a full Octomap message (as octomap_msgs::fullMapToMsg writes it): binary false, id
/// "OcTree", resolution in metres, data as OcTree::writeData writes it, with each node's
/// log-odds occupancy.
sift_hull::Octomap octomapFullMessage(const octomap::OcTree& tree, const std_msgs::Header& header);
/// The same for OctoMap's ColorOcTree: id "ColorOcTree", each node's colour after its occupancy
/// (octomap_server's colour mode; rviz's octomap plugin shows the colours).
sift_hull::Octomap octomapFullMessage(const octomap::ColorOcTree& tree,
                                      const std_msgs::Header& header);

/// The tree a binary or full Octomap message holds, read as octomap_msgs::msgToMap reads it
/// (OcTree::readBinaryData or OcTree::readData); empty data is an empty tree. Throws
/// std::invalid_argument for an id other than "OcTree", a resolution that is not a positive
/// number, or data cut short.
std::unique_ptr<octomap::OcTree> octreeFromMessage(const sift_hull::Octomap& message);

/// Points (metres, in the header's frame) as an XYZ PointCloud2 (via pcl_conversions).
sensor_msgs::PointCloud2 pointCloudMessage(const std::vector<Eigen::Vector3d>& points,
                                           const std_msgs::Header& header);

/// Coloured points as an XYZRGB PointCloud2 (PCL's PointXYZRGB: `rgb` a float holding 0x00RRGGBB),
/// one colour (red, green, blue) per point; throws std::invalid_argument when the counts differ.
sensor_msgs::PointCloud2 pointCloudMessage(const std::vector<Eigen::Vector3d>& points,
                                           const std::vector<std::array<uint8_t, 3>>& colours_rgb,
                                           const std_msgs::Header& header);

/// Occupied leaf centres of the tree, metres, as an XYZ PointCloud2 (via pcl_conversions).
sensor_msgs::PointCloud2 occupiedCellsCloud(const octomap::OcTree& tree,
                                            const std_msgs::Header& header);

/// Occupied leaves as CUBE_LIST markers, one per depth level 0..tree depth with id = level
/// (octomap_server's occupied_cells_vis_array), coloured by height; a level without occupied
/// leaves has action DELETE, so rviz drops what it showed there.
visualization_msgs::MarkerArray occupiedCellsMarkers(const octomap::OcTree& tree,
                                                     const std_msgs::Header& header);

/// The box between two corners (a BoundingBoxQuery request's min and max, metres), as given:
/// not checked (isValidClearBox checks it).
Box3d boxFromCorners(const geometry_msgs::Point& min, const geometry_msgs::Point& max);

/// "(x, y, z)", for messages.
std::string pointText(const geometry_msgs::Point& point);

/// A marker of `type` (visualization_msgs::Marker::LINE_LIST, ...) to ADD in namespace `ns` with
/// `header`, an identity pose, unit scale and opaque `colour`: what the hull node's markers share.
visualization_msgs::Marker marker(const std_msgs::Header& header, const std::string& ns,
                                  int32_t type, const std_msgs::ColorRGBA& colour);
/// An opaque colour.
std_msgs::ColorRGBA colour(float r, float g, float b);

/// A box's twelve edges as a LINE_LIST marker in the header's frame (namespace "carving_box",
/// yellow, lines 1 % of the box's longest edge wide).
visualization_msgs::Marker boxMarker(const Box3d& box_W, const std_msgs::Header& header);

/// Free leaves as CUBE_LIST markers, one per depth level as occupiedCellsMarkers (octomap_server's
/// free_cells_vis_array), blue, in namespace "free_cells".
visualization_msgs::MarkerArray freeCellsMarkers(const octomap::OcTree& tree,
                                                 const std_msgs::Header& header);

/// One DELETEALL marker stamped `header`: rviz removes every marker of the topic (the hull node
/// after ~reset).
visualization_msgs::MarkerArray deleteAllMarkers(const std_msgs::Header& header);

/// The mesh as a TRIANGLE_LIST marker in the header's frame, metres.
visualization_msgs::Marker meshMarker(const TriangleMesh& mesh, const std_msgs::Header& header);

/// A keypoint as a message: position (pixels), size, angle (degrees), response, octave as OpenCV
/// holds them.
sift_hull::Keypoint keypointMessage(const cv::KeyPoint& keypoint);

/// Every putative match with the decision of each filter: bit f of `kept_by` set when
/// `results[f]` keeps the match (`filter_names[f]` names it), `gsc_score` the score of the filter
/// named "gsc" (NaN without one), the left image's header, the right one's as `right_header`.
/// Throws std::invalid_argument when names and results differ in number, a result has not one
/// entry per match, or there are more than 32 filters.
sift_hull::Correspondences correspondencesMessage(const std_msgs::Header& left_header,
                                                  const std_msgs::Header& right_header,
                                                  const std::vector<std::string>& filter_names,
                                                  const std::string& settings_json,
                                                  const PutativeMatches& matches,
                                                  const std::vector<FilterResult>& results);

/// The matching and filter settings as the JSON object of Correspondences.filter_settings, keyed
/// by the names of their settings (sift_hull/settings.h), which are the ROS parameters' names.
std::string settingsJson(const MatchConfig& matching, const FilterConfigs& filters);

/// A pair's surface points (triangulatePair) and its two cameras (lens distortion dropped: the
/// message's cameras are pinhole), in the header's frame.
sift_hull::SurfacePoints surfacePointsMessage(const std_msgs::Header& header,
                                              const PinholeCamera& left, const PinholeCamera& right,
                                              const std::vector<SurfacePoint>& points);

/// A SurfacePoints message taken into the world frame by T_W_F (the message's frame in the world):
/// its two cameras, and its points with views 0 (left) and 1 (right), their depth sigma from the
/// cameras. False, with `why_not`, for arrays of different lengths, a value that is not finite, a
/// negative reprojection error, or a camera PinholeCamera refuses (K, R). Every point is checked;
/// at most `max_points` are converted, evenly spread in the message's order.
bool surfacePointsFromMessage(const sift_hull::SurfacePoints& message,
                              const Eigen::Isometry3d& T_W_F, PinholeCamera* left,
                              PinholeCamera* right, std::vector<SurfacePoint>* points,
                              std::string* why_not,
                              size_t max_points = std::numeric_limits<size_t>::max());

}  // namespace ros_conversions
}  // namespace sift_hull
