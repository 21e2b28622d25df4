#pragma once

#include <string>
#include <vector>

#include "sift_hull/io/calibration.h"

namespace sift_hull {

/// Reads a NeRF / instant-ngp `transforms.json` (or `transforms_train.json`, ...): its "frames",
/// in the file's order, each a view named by its "file_path" relative to the json's directory
/// ("./" dropped; without an extension, the first of .png, .jpg, .jpeg, .PNG, .JPG that exists
/// beside it, else .png), its "transform_matrix" camera-to-world in the OpenGL / Blender
/// convention (the camera looks along -z with y up; the last row must be 0 0 0 1 and the upper
/// left 3x3 a rotation).
///
/// Intrinsics per file, each overridden per frame: "fl_x" / "fl_y" (else "camera_angle_x" /
/// "camera_angle_y", full field-of-view angles in radians; fl_y defaults to fl_x), "cx" / "cy"
/// (instant-ngp's convention, the top-left pixel spanning [0, 1]: cx - 0.5 in this package's,
/// where pixel centres are integers; default the image centre, (w - 1) / 2 here), "w" / "h" (else
/// the image file's size), and "k1", "k2", "p1", "p2" (OpenCV's radial-tangential model).
/// The world frame is the file's. Throws ParseError "FILE: frame I (NAME): what" for malformed
/// JSON, a missing or non-numeric field, a non-finite value, a matrix that is not a rigid
/// transform, a focal length that is not positive, or an image size that cannot be found.
std::vector<CalibratedView> readNerfTransforms(const std::string& path);

/// A directory's NeRF files, when it holds no COLMAP model: `transforms.json`, else
/// `transforms_train.json`, `transforms_val.json` and `transforms_test.json` (those present, in
/// that order). Empty when it holds none.
std::vector<std::string> nerfTransformFiles(const std::string& directory);

/// Writes views as a `transforms.json` readNerfTransforms reads back to the same projections (to
/// 1e-12): fl_x, fl_y, cx, cy, w, h per frame, the distortion's k1, k2, p1, p2; file_path is the
/// view's name. Throws std::runtime_error for a view with a skewed K, a mirrored world frame or
/// distortion beyond k1, k2, p1, p2, or when the file cannot be written.
void writeNerfTransforms(const std::string& path, const std::vector<CalibratedView>& views,
                         int width_px, int height_px);

}  // namespace sift_hull
