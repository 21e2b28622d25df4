#pragma once

#include <functional>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "sift_hull/hull/run_length_mask.h"
#include "sift_hull/hull/silhouette.h"
#include "sift_hull/hull/view_silhouettes.h"
#include "sift_hull/io/calibration.h"

namespace sift_hull {

/// Reads an image with cv::imread's `imread_flags` (a colour image by default); throws
/// std::runtime_error "PATH: image missing or unreadable".
cv::Mat readImage(const std::string& path, int imread_flags = cv::IMREAD_COLOR);

/// Throws std::runtime_error naming the camera line (view.size_source) with its size and the image
/// `image_path` with its own when the view's calibration gives an image size (width_px x
/// height_px) other than `image_size`.
void checkImageSize(const CalibratedView& view, cv::Size image_size, const std::string& image_path);

/// Reads the image a view names, from `directory`. Throws std::runtime_error naming the image and
/// the calibration line that names it when the view has no image name or the image is missing or
/// cannot be decoded, and as checkImageSize when its size is not the calibration's. Colour images
/// come back as BGR, 8 bits per channel.
cv::Mat loadViewImage(const std::string& directory, const CalibratedView& view);

/// A view's image and, when the file has an alpha channel that is not constant, the silhouette it
/// holds: alpha at least half of full scale (CV_8UC1, 255 inside); else alpha_mask is empty.
struct ViewImage {
  cv::Mat bgr;         ///< as loadViewImage gives it
  cv::Mat alpha_mask;  ///< empty without a varying alpha channel
};

/// loadViewImage(), keeping the alpha channel of a PNG, TIFF or WebP image as its silhouette (the
/// NeRF synthetic scenes' RGBA images, cut-outs). Other files are decoded as loadViewImage does.
ViewImage loadViewImageWithAlpha(const std::string& directory, const CalibratedView& view);

/// loadViewImageWithAlpha() reduced `reduction` times (1, 2, 4 or 8), the image and its alpha mask
/// alike: a JPEG decoded at that scale (readImageReduced), another file decoded whole and reduced
/// by area (reduceImage, reduceMask). `full_size` gets the image's full size, which is checked
/// against the view's calibration (checkImageSize). Throws as loadViewImageWithAlpha() does.
ViewImage loadReducedViewImage(const std::string& directory, const CalibratedView& view,
                               int reduction, cv::Size* full_size);

/// The mask file of an image in `mask_directory`: the image's own name when that file exists,
/// else the one file whose name is the same number under another width or extension
/// (image/000012.png and mask/012.png in IDR / DTU sets); else the own name, which the reader
/// then reports missing.
std::string maskPath(const std::string& mask_directory, const std::string& image_name);

/// Reads a mask file: inside where the value exceeds half the file's largest (maskInside: any
/// non-zero pixel of a 0/1 or 0/255 mask, not a JPEG's ringing). Returns CV_8UC1 with 255 inside.
/// Throws std::runtime_error naming the file when it is missing or unreadable.
cv::Mat loadMask(const std::string& path);

/// Silhouettes of all views, in view order: the mask file of each view (maskPath) in
/// `mask_directory` when that is not empty, else the image's alpha channel when it has a varying
/// one (loadViewImageWithAlpha), else extracted from the view's image in `image_directory` by
/// `recipe`; by the "views" method (silhouettesFromViews), all views' images together, their
/// cameras the views', and `report`, when given, gets what it found (priors, hull projections,
/// support, warnings; not the masks). Mask files may hold 1, 3 or 4 channels: any non-zero grey
/// level is inside.
/// Throws std::runtime_error naming a missing or unreadable file, a mask whose size differs from
/// its image's, or an image whose size differs from the first view's.
std::vector<cv::Mat> loadSilhouettes(const std::vector<CalibratedView>& views,
                                     const std::string& image_directory,
                                     const std::string& mask_directory,
                                     const SilhouetteConfig& recipe,
                                     ViewSilhouettes* report = nullptr);

/// loadSilhouettes(), each silhouette run-length encoded as soon as it is made: at most one
/// full-resolution image and mask per thread stays in memory at a time.
std::vector<RunLengthMask> loadRunLengthSilhouettes(const std::vector<CalibratedView>& views,
                                                    const std::string& image_directory,
                                                    const std::string& mask_directory,
                                                    const SilhouetteConfig& recipe,
                                                    ViewSilhouettes* report = nullptr);

/// loadRunLengthSilhouettes() of photographs read `reduction` times reduced (1, 2, 4 or 8;
/// loadReducedViewImage): the silhouettes are made at that size, by the recipe with its radii
/// (dilate_px, erode_px, in full-resolution pixels) divided by it, the "views" method with the
/// cameras PinholeCamera::reduced() alike; each is reducedSize(image size, reduction). A mask
/// directory needs `reduction` 1. `on_view_read(read, total)`, when given, is called from
/// OpenCV's threads (at times at once) as each view is read.
std::vector<RunLengthMask> loadReducedRunLengthSilhouettes(
    const std::vector<CalibratedView>& views, const std::string& image_directory,
    const std::string& mask_directory, const SilhouetteConfig& recipe, int reduction,
    ViewSilhouettes* report = nullptr,
    const std::function<void(size_t read, size_t total)>& on_view_read = {});

}  // namespace sift_hull
