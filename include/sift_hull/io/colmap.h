#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <istream>
#include <map>
#include <string>
#include <vector>

#include "sift_hull/io/calibration.h"

namespace sift_hull {

/// One camera (intrinsics) of a COLMAP sparse model, in this package's pixel convention: COLMAP
/// puts (0, 0) at the top-left image corner, so cx and cy are taken 0.5 pixel smaller here.
struct ColmapCamera {
  std::string model;  ///< "SIMPLE_PINHOLE", "PINHOLE", "SIMPLE_RADIAL", "RADIAL", "OPENCV", ...
  uint64_t width_px = 0;
  uint64_t height_px = 0;
  Eigen::Matrix3d K = Eigen::Matrix3d::Identity();
  LensDistortion distortion;
  /// Where the camera is written: "cameras.txt:LINE", or "cameras.bin (camera ID at byte N)".
  std::string source;
};

/// Reads a COLMAP sparse model directory: the text model (cameras.txt, images.txt) when both exist,
/// else the binary model (cameras.bin, images.bin). Each image becomes a view with the camera
/// K [R | t], R from the quaternion (qw, qx, qy, qz; normalised when its norm is within 0.01 of 1,
/// refused naming its norm otherwise) and t as written (world to camera). In images.txt each
/// image line may be followed by its POINTS2D line (empty or not) or not: the points are checked
/// as read and not kept. Each view carries its camera's WIDTH x HEIGHT (CalibratedView::width_px,
/// height_px), which loadViewImage checks against the image. Models SIMPLE_PINHOLE, PINHOLE,
/// SIMPLE_RADIAL, RADIAL, OPENCV and FULL_OPENCV (with k4 = k5 = k6 = 0) are read; others are
/// refused by name. Views are sorted by image name. Throws ParseError naming the file (and the line
/// for text files).
std::vector<CalibratedView> readColmapModel(const std::string& directory);

/// True when `directory` holds cameras.txt and images.txt, or cameras.bin and images.bin.
bool isColmapModel(const std::string& directory);

/// "COLMAP text (cameras.txt, images.txt)" or "COLMAP binary (cameras.bin, images.bin)".
std::string colmapModelFormat(const std::string& directory);

/// Parses COLMAP's cameras.bin from a stream of `size_bytes` bytes; `file` names it in errors.
std::map<uint32_t, ColmapCamera> parseColmapCamerasBinary(std::istream& in, uint64_t size_bytes,
                                                          const std::string& file);

/// Parses COLMAP's images.bin from a stream of `size_bytes` bytes into views using `cameras`;
/// `file` names it in errors. The views are in the file's order.
std::vector<CalibratedView> parseColmapImagesBinary(
    std::istream& in, uint64_t size_bytes, const std::string& file,
    const std::map<uint32_t, ColmapCamera>& cameras);

/// Writes views as a COLMAP text model into `directory` (created when missing): cameras.txt with
/// one camera per view, PINHOLE without distortion, OPENCV with k1, k2, p1, p2, FULL_OPENCV when k3
/// is not zero (cx, cy written 0.5 larger, COLMAP's convention), and images.txt with each view's
/// pose and an empty point line; 17 significant digits, so readColmapModel gives the views back.
/// Every view has the image size `width_px` x `height_px`. Throws std::runtime_error naming the
/// view for a camera with skew or a mirrored frame (det R = -1), which COLMAP cannot hold.
void writeColmapText(const std::string& directory, const std::vector<CalibratedView>& views,
                     int width_px, int height_px);

}  // namespace sift_hull
