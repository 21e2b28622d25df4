#pragma once

#include <stdexcept>
#include <string>
#include <vector>

#include "sift_hull/geometry/camera.h"

namespace sift_hull {

/// Malformed input file. what() reads "FILE:LINE: message" (no ":LINE" when no line is at fault).
class ParseError : public std::runtime_error {
 public:
  ParseError(const std::string& file, int line, const std::string& message);
  const std::string& file() const { return file_; }
  int line() const { return line_; }

 private:
  std::string file_;
  int line_;
};

/// One calibrated view: the image file it names and its camera.
struct CalibratedView {
  std::string name;  ///< image file name as written in the calibration file (may be empty)
  PinholeCamera camera;
  std::string source;  ///< "FILE:LINE" the view was read from; empty when made in code
};

/// Reads a Middlebury `*_par.txt`: a count line, then one line per view
/// `name k11 k12 k13 k21 k22 k23 k31 k32 k33 r11 r12 r13 r21 r22 r23 r31 r32 r33 t1 t2 t3`.
/// Throws ParseError naming the file and line on a missing or malformed count line, a count outside
/// 1..1000000, a wrong field count, a non-number, NaN or infinity, a singular K, an R that is not a
/// rotation, or a count line that disagrees with the lines.
std::vector<CalibratedView> readMiddleburyPar(const std::string& path);

/// Reads a list of 3x4 projection matrices, one per line as 12 row-major numbers, each optionally
/// preceded by an image name (which must not be a number). Blank lines and lines starting with '#'
/// are skipped. Throws ParseError naming the file and line.
std::vector<CalibratedView> readProjectionList(const std::string& path);

/// Reads either format: a first line holding a single integer means a Middlebury par file. A first
/// line shaped like a par line (a name and 21 numbers) is reported as a missing count line.
std::vector<CalibratedView> readCalibration(const std::string& path);

/// Writes views as a Middlebury par file (17 significant digits, so reading it back is exact).
void writeMiddleburyPar(const std::string& path, const std::vector<CalibratedView>& views);

/// The cameras of the views, in order.
std::vector<PinholeCamera> camerasOf(const std::vector<CalibratedView>& views);

/// Directory of a file path ("." when it has none).
std::string parentDirectory(const std::string& path);

}  // namespace sift_hull
