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
};

/// Reads a COLMAP sparse model directory: the text model (cameras.txt, images.txt) when both exist,
/// else the binary model (cameras.bin, images.bin). Each image becomes a view with the camera
/// K [R | t], R from the quaternion (qw, qx, qy, qz, normalised) and t as written (world to
/// camera). Models SIMPLE_PINHOLE, PINHOLE, SIMPLE_RADIAL, RADIAL, OPENCV and FULL_OPENCV (with
/// k4 = k5 = k6 = 0) are read; others are refused by name. Views are sorted by image name. Throws
/// ParseError naming the file (and the line for text files).
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

}  // namespace sift_hull
