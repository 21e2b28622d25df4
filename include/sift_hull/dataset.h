#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "sift_hull/camera.h"

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

/// Directory of a file path ("." when it has none).
std::string parentDirectory(const std::string& path);

/// Reads a colour image; throws std::runtime_error "PATH: image missing or unreadable".
cv::Mat readImage(const std::string& path);

/// Reads the image a view names, from `directory`. Throws std::runtime_error naming the image and
/// the calibration line that names it when the view has no image name or the image is missing or
/// cannot be decoded. Colour images come back as BGR, 8 bits per channel.
cv::Mat loadViewImage(const std::string& directory, const CalibratedView& view);

/// Silhouette extraction by the Middlebury recipe: grey intensity above `threshold` (on [0, 1]),
/// then a dilation and an erosion with discs of the given radii.
struct SilhouetteConfig {
  double threshold = 0.19;
  int dilate_px = 10;
  int erode_px = 7;
};

/// Throws std::invalid_argument for a threshold outside [0, 1] or a radius outside
/// [0, limits::kMaxMorphologyRadiusPx].
void validate(const SilhouetteConfig& config);

/// Mask (CV_8UC1, 255 inside, 0 outside) of the object in an 8-bit grey or BGR image.
cv::Mat silhouetteFromImage(const cv::Mat& image, const SilhouetteConfig& config);

/// Reads a mask file: any non-zero pixel is inside. Returns CV_8UC1 with 255 inside.
/// Throws std::runtime_error naming the file when it is missing or unreadable.
cv::Mat loadMask(const std::string& path);

/// Silhouettes of all views, in view order: the mask file of each view's name in `mask_directory`
/// when that is not empty, else extracted from the view's image in `image_directory` by `recipe`.
/// Throws std::runtime_error naming a missing or unreadable file, a mask whose size differs from
/// its image's, or an image whose size differs from the first view's.
std::vector<cv::Mat> loadSilhouettes(const std::vector<CalibratedView>& views,
                                     const std::string& image_directory,
                                     const std::string& mask_directory,
                                     const SilhouetteConfig& recipe);

/// Where the views' optical axes come closest to meeting (least squares over the axes).
struct CommonPoint {
  Eigen::Vector3d point_W = Eigen::Vector3d::Zero();
  /// Largest distance of the point from an optical axis, in world units (metres for scenes).
  double max_axis_distance_m = 0.0;
  bool in_front_of_all = false;  ///< the point has positive depth in every view
  bool well_defined = false;     ///< the axes are not all parallel (needs two views or more)
};

CommonPoint opticalAxesMeetingPoint(const std::vector<CalibratedView>& views);

}  // namespace sift_hull
