#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "sift_hull/geometry/camera.h"
#include "sift_hull/geometry/distortion.h"

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
  std::string name;      ///< image file name as written in the calibration file (may be empty)
  PinholeCamera camera;  ///< with the lens distortion the calibration gives, if any
  std::string source;    ///< "FILE:LINE" the view was read from; empty when made in code
  /// Camera model of the calibration: a COLMAP model name ("PINHOLE", "OPENCV", ...), "LLFF",
  /// "NeRF", "IDR", "par" or "projection"; empty when made in code.
  std::string camera_model;
  /// Image size the calibration gives for the view (a COLMAP camera's WIDTH and HEIGHT); 0 when
  /// it gives none. checkImageSize compares it with the image.
  uint64_t width_px = 0;
  uint64_t height_px = 0;
  /// Where that size is written ("FILE:LINE" of the camera); empty when no size is given.
  std::string size_source;
};

/// Reads a Middlebury `*_par.txt`: a count line, then one line per view
/// `name k11 k12 k13 k21 k22 k23 k31 k32 k33 r11 r12 r13 r21 r22 r23 r31 r32 r33 t1 t2 t3`.
/// Throws ParseError naming the file and line on a missing or malformed count line, a count outside
/// 1..1000000, a wrong field count, a non-number, NaN or infinity, a singular K, an R that is not a
/// rotation, or a count line that disagrees with the lines.
std::vector<CalibratedView> readMiddleburyPar(const std::string& path);

/// Reads a list of 3x4 projection matrices, each either on one line as 12 row-major numbers or on
/// three lines of 4 numbers (a row each), optionally preceded by an image name (which must not be
/// a number) on the first row or alone on the line before. Numbers may be separated by white space
/// or commas. Blank lines and lines starting with '#' are skipped. Throws ParseError naming the
/// file and line.
std::vector<CalibratedView> readProjectionList(const std::string& path);

/// Reads any calibration format: a directory is NeRF transforms (nerfTransformFiles, when it
/// holds them and no COLMAP cameras file), IDR cameras (its cameras.npz, else its
/// cameras_sphere.npz, when it holds neither a COLMAP cameras file nor NeRF transforms:
/// idrCamerasFile) or a COLMAP sparse model (readColmapModel); a file ending in ".json" NeRF
/// transforms (readNerfTransforms), one ending in ".npy" LLFF poses (readLlffPoses, the views
/// being the sorted images of `image_directory`), one ending in ".npz" IDR / NeuS / VolSDF
/// cameras (readIdrCameras, the views being the sorted images of `image_directory`, or of the
/// file's image/ sub-directory when it is empty); else a text file: a first line holding a
/// single integer means a Middlebury par file, otherwise a projection list. A first line shaped
/// like a par line (a name and 21 numbers) is reported as a missing count line.
std::vector<CalibratedView> readCalibrationWithImages(const std::string& path,
                                                      const std::string& image_directory);

/// readCalibrationWithImages(path, parentDirectory(path)); for IDR cameras (idrCamerasFile)
/// readCalibrationWithImages(path, ""): the images of the file's image/ sub-directory.
std::vector<CalibratedView> readCalibration(const std::string& path);

/// Human-readable name of the format readCalibration() reads at `path`, such as
/// "COLMAP text (cameras.txt, images.txt)", "COLMAP binary (cameras.bin, images.bin)",
/// "NeRF transforms.json", "LLFF poses_bounds.npy", "IDR cameras.npz", "Middlebury par" or
/// "projection list". Does
/// not validate the file.
std::string calibrationFormat(const std::string& path);

/// "no distortion" or "k1=... k2=... p1=... p2=... k3=..." (the non-zero coefficients).
std::string describeDistortion(const LensDistortion& distortion);

/// Writes views as a Middlebury par file (17 significant digits, so reading it back is exact).
/// Throws std::runtime_error for a mirrored or distorted camera, which the format cannot hold.
void writeMiddleburyPar(const std::string& path, const std::vector<CalibratedView>& views);

/// The cameras of the views, in order.
std::vector<PinholeCamera> camerasOf(const std::vector<CalibratedView>& views);

/// Directory of a file path ("." when it has none).
std::string parentDirectory(const std::string& path);

}  // namespace sift_hull
