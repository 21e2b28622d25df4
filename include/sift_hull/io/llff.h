#pragma once

#include <cstdint>
#include <istream>
#include <string>
#include <vector>

#include "sift_hull/io/calibration.h"

namespace sift_hull {

/// A two-dimensional float64 (or float32, widened) array read from a .npy file, stored row-major.
struct NpyMatrix {
  uint64_t rows = 0;
  uint64_t cols = 0;
  std::vector<double> values;  ///< rows x cols, row-major whatever the file's order
  /// Element (row, col).
  double at(uint64_t row, uint64_t col) const { return values[row * cols + col]; }
};

/// Parses a .npy file (format versions 1.0, 2.0 and 3.0) of `size_bytes` bytes holding a
/// little-endian float64 ('<f8') array of shape (N, `cols`), in C or Fortran order; N must be
/// `rows` when that is not 0, and with `allow_float32` a little-endian float32 ('<f4') array is
/// read too. Throws ParseError "FILE: what" for a bad magic string, version, header, dtype, shape
/// or a file whose length does not match the shape.
NpyMatrix parseNpyMatrix(std::istream& in, uint64_t size_bytes, const std::string& file,
                         uint64_t cols, uint64_t rows = 0, bool allow_float32 = false);

/// Reads LLFF's poses_bounds.npy: N x 17 float64, each row a 3x5 matrix (the camera-to-world
/// rotation's columns in LLFF's [down, right, backwards] axes, the camera centre, and [height,
/// width, focal]) then the near and far bounds. View i is named image_names[i] (the sorted image
/// files: listImageFiles()); a count mismatch is refused naming both counts. K has the principal
/// point at the image centre ((W - 1) / 2, (H - 1) / 2 in this package's pixel convention).
/// `image_width_px` x `image_height_px`, when not zero, is the size of the images used: LLFF's
/// downscaled copies (images_4/, images_8/) keep the full-resolution [height, width, focal], so K
/// is scaled to the images' size; a size that is not the poses' scaled by one factor (to a pixel's
/// rounding) is refused naming both sizes.
std::vector<CalibratedView> readLlffPoses(const std::string& npy_path,
                                          const std::vector<std::string>& image_names,
                                          int image_width_px = 0, int image_height_px = 0);

/// The image files (.png, .jpg, .jpeg, any case) directly in `directory`, sorted by name. Throws
/// std::runtime_error when the directory cannot be read.
std::vector<std::string> listImageFiles(const std::string& directory);

}  // namespace sift_hull
