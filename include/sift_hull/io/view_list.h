#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "sift_hull/hull/hull_pipeline.h"
#include "sift_hull/hull/silhouette.h"
#include "sift_hull/hull/view_silhouettes.h"
#include "sift_hull/io/calibration.h"

namespace sift_hull {

/// Image names listed in a file, one per line; blank lines and '#' comments skipped.
std::vector<std::string> readViewList(const std::string& path);

/// The views of a calibration file named in `view_names` (all when empty), in the file's order,
/// read by readCalibrationWithImages(calibration_path, image_directory). Throws
/// std::runtime_error for a name that the calibration does not hold.
std::vector<CalibratedView> hullViews(const std::string& calibration_path,
                                      const std::string& image_directory,
                                      const std::vector<std::string>& view_names);

/// The views of a calibration file named in `view_names` (all when empty), in the file's order,
/// with silhouettes as loadSilhouettes() finds them. Throws std::runtime_error for a name that the
/// calibration does not hold. Cameras keep their lens distortion; the hull carves raw silhouettes
/// with it (HullView).
/// The calibration is read by readCalibrationWithImages(calibration_path, image_directory).
HullInput loadHullInput(const std::string& calibration_path, const std::string& image_directory,
                        const std::string& mask_directory, const SilhouetteConfig& recipe,
                        const std::vector<std::string>& view_names,
                        ViewSilhouettes* report = nullptr);

/// loadHullInput() with the silhouettes run-length encoded as they are read
/// (HullInput::run_length_masks, `masks` empty): no full-resolution mask is kept.
HullInput loadRunLengthHullInput(const std::string& calibration_path,
                                 const std::string& image_directory,
                                 const std::string& mask_directory, const SilhouetteConfig& recipe,
                                 const std::vector<std::string>& view_names,
                                 ViewSilhouettes* report = nullptr);

/// Reduced loading, for silhouettes given as mask files: each view's mask is decoded at the
/// largest of the reductions 1, 2, 4 and 8, at most `max_reduction`, that the finest voxel's
/// footprint in that view allows (distanceReduction()'s pixels per finest voxel at the box's far
/// side, rounded down to one of them; 1 below 2 MP), and its camera is PinholeCamera::reduced()
/// by it (HullInput::reductions, HullInput::image_sizes). The box is `box`, or the LP box of the
/// masks decoded at `max_reduction` first. JPEG masks are decoded at their reduction directly
/// (readMaskReduced); others are decoded once at full resolution and reduced from it. Image
/// sizes (of `image_directory`'s images, when given, and of the masks) are read from the files'
/// headers (imageFileSize) and checked as loadHullInput checks them. `max_reduction` 1 gives
/// loadRunLengthHullInput's full-resolution input. The work runs on OpenCV's threads;
/// `on_view_read(read, total)`, when given, is called from them (at times at once) as each view's
/// mask is read at its reduction.
HullInput loadReducedHullInput(
    const std::string& calibration_path, const std::string& image_directory,
    const std::string& mask_directory, const std::vector<std::string>& view_names,
    const HullConfig& config, const std::optional<Box3d>& box, int max_reduction,
    const std::function<void(size_t read, size_t total)>& on_view_read = {});

/// The reduction (1, 2, 4 or 8, at most `max_reduction`) at which photographs of `image_size` are
/// read and segmented for a hull of `max_depth`: the largest at which the finest voxel still
/// covers a pixel when the hull's box spans half the image's longest side, and the image keeps
/// `segment_side_px` (the "views" method's working size) on its longest side; 1 below 2 MP
/// (kMinReducedImagePixels), as for mask files.
int photographReduction(cv::Size image_size, int max_depth, int segment_side_px, int max_reduction);

/// Reduced loading, for silhouettes segmented from the photographs (no mask files): every view is
/// read at photographReduction() of the first image's size (from its header) and segmented at that
/// size (loadReducedRunLengthSilhouettes), its camera PinholeCamera::reduced() alike
/// (HullInput::reductions, HullInput::image_sizes). `report` and `on_view_read` as there;
/// `max_reduction` 1 gives loadRunLengthHullInput's input.
HullInput loadReducedPhotoHullInput(
    const std::string& calibration_path, const std::string& image_directory,
    const std::vector<std::string>& view_names, const SilhouetteConfig& recipe,
    const HullConfig& config, int max_reduction, ViewSilhouettes* report = nullptr,
    const std::function<void(size_t read, size_t total)>& on_view_read = {});

}  // namespace sift_hull
