#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "sift_hull/hull/bounding_box.h"
#include "sift_hull/io/calibration.h"

namespace sift_hull {

/// The matrices of an IDR / NeuS / VolSDF camera file (`cameras.npz`, `cameras_sphere.npz`): a
/// numpy .npz archive of 4x4 float64 or float32 arrays.
struct IdrCameras {
  /// world_mat_0 .. world_mat_{N-1}: the top 3x4 block is the view's P = K [R | t] up to scale,
  /// the last row 0 0 0 1.
  std::vector<Eigen::Matrix4d> world_mats;
  /// scale_mat_0, when the file holds it: it maps the unit sphere around the object to the world
  /// (centre its translation column, radius its scale).
  std::optional<Eigen::Matrix4d> scale_mat;
};

/// Reads the world_mat_I entries (I = 0 .. N-1, no gaps) and scale_mat_0 of an IDR camera file;
/// other entries (camera_mat_I, world_mat_inv_I, scale_mat_inv_I, ...) are not read. Throws
/// ParseError "FILE: what" (what naming the entry) for a file that is not a zip archive, a
/// missing, truncated, corrupt or encrypted entry, one decompressing to more than
/// limits::kMaxNpzEntryBytes, an entry that is not a 4x4 float64 or float32 .npy array, a
/// non-finite value, a last row other than 0 0 0 1, a singular scale_mat_0, a gap in the indices,
/// no world_mat_0, or more than limits::kMaxCalibrationViews views.
IdrCameras readIdrCameraMatrices(const std::string& npz_path);
/// The same for the file's bytes held in memory; `name` stands for the file in errors.
IdrCameras parseIdrCameraMatrices(const std::string& bytes, const std::string& name);

/// The views of the matrices: view I is world_mat_I's camera named image_names[I] (a count
/// mismatch is refused naming both counts), P decomposed by PinholeCamera::fromProjection (K with
/// a positive diagonal and K(2,2) = 1), in world_mat's own frame (scale_mat does not normalise
/// it). P's sign is chosen so that scale_mat_0's centre, the object, lies in front of every
/// camera; a mirrored world frame gives improper cameras, and views that disagree on the frame's
/// handedness are refused naming them. Without scale_mat_0 the views are oriented as a projection
/// list's (orientViews: where the optical axes meet). Pixel centres are integers, as in IDR's and
/// NeuS's ray sampling: K is used as it is. Throws ParseError for `npz_path` naming the entry.
std::vector<CalibratedView> idrViews(const IdrCameras& cameras,
                                     const std::vector<std::string>& image_names,
                                     const std::string& npz_path);

/// The directory whose images an IDR camera file's views are: `image_directory`, or when that is
/// empty the file's own `image/` sub-directory (DTU's layout: image/000000.png, mask/000.png).
std::string idrImageDirectory(const std::string& npz_path, const std::string& image_directory);

/// readIdrCameraMatrices then idrViews with the sorted image files (listImageFiles) of
/// idrImageDirectory(npz_path, image_directory).
std::vector<CalibratedView> readIdrCameras(const std::string& npz_path,
                                           const std::string& image_directory = "");

/// The IDR camera file at `path`: `path` itself when it is a file ending in ".npz"; for a
/// directory with no COLMAP cameras file (cameras.bin, cameras.txt) and no NeRF transforms json,
/// its `cameras.npz`, else its `cameras_sphere.npz`; else empty.
std::string idrCamerasFile(const std::string& path);

/// The axis-aligned box around the unit sphere scale_mat_0 maps to the world (centre plus or
/// minus the radius, for IDR's and NeuS's scale_mat); empty without a scale_mat_0.
std::optional<Box3d> idrObjectBox(const IdrCameras& cameras);
/// The same for the file idrCamerasFile(path) names; empty when there is none. Throws ParseError
/// as readIdrCameraMatrices.
std::optional<Box3d> idrObjectBox(const std::string& path);

/// Writes views as an uncompressed IDR camera file (as np.savez writes): world_mat_I.npy, K [R | t]
/// as a 4x4 float64 array with the last row 0 0 0 1, and scale_mat_I.npy = scale_mat for each
/// view. The file names no image: view I is the I-th image by name. Throws std::runtime_error for
/// a view with lens distortion, which the format cannot hold, or when the file cannot be written.
void writeIdrCameras(const std::string& path, const std::vector<CalibratedView>& views,
                     const Eigen::Matrix4d& scale_mat);

}  // namespace sift_hull
