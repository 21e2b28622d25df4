#pragma once

#include <string>
#include <vector>

#include "sift_hull/hull/hull_pipeline.h"
#include "sift_hull/hull/silhouette.h"
#include "sift_hull/hull/view_silhouettes.h"

namespace sift_hull {

/// Image names listed in a file, one per line; blank lines and '#' comments skipped.
std::vector<std::string> readViewList(const std::string& path);

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

}  // namespace sift_hull
