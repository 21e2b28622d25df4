// Reduced loading of a view set (sift_hull/io/view_list.h): with mask files
// (loadReducedHullInput), or with photographs to segment (loadReducedPhotoHullInput).

#include <algorithm>
#include <atomic>
#include <cmath>
#include <exception>
#include <opencv2/core/utility.hpp>
#include <stdexcept>

#include "sift_hull/geometry/camera_set.h"
#include "sift_hull/hull/bounding_box.h"
#include "sift_hull/hull/reduced_distance_map.h"
#include "sift_hull/io/images.h"
#include "sift_hull/io/reduced_images.h"
#include "sift_hull/io/view_list.h"

namespace sift_hull {
namespace {

/// The largest of 1, 2, 4 and 8 not above `value`.
int decodableAtMost(int value) {
  int reduction = 1;
  while (reduction * 2 <= value && reduction < 8) reduction *= 2;
  return reduction;
}

/// What the first pass learns of one view.
struct FirstPass {
  std::string mask_path;
  cv::Size size;         ///< the image's (and its mask's) full size
  bool jpeg = false;     ///< decoded again at its reduction in the second pass
  RunLengthMask full;    ///< any other mask, decoded once at full resolution
  RunLengthMask coarse;  ///< at max_reduction, for the box
  std::exception_ptr error;
};

FirstPass readFirst(const std::string& image_directory, const std::string& mask_directory,
                    const CalibratedView& view, int coarse_reduction) {
  FirstPass read;
  if (view.name.empty()) {
    throw std::runtime_error((view.source.empty() ? "a view" : view.source) +
                             ": no image name for this view; put one before its numbers");
  }
  read.mask_path = maskPath(mask_directory, view.name);
  const cv::Size mask_size = imageFileSize(read.mask_path);
  if (!image_directory.empty()) {
    const std::string image_path = image_directory + "/" + view.name;
    read.size = imageFileSize(image_path);
    checkImageSize(view, read.size, image_path);
    if (mask_size != read.size) {
      throw std::runtime_error(read.mask_path + ": mask size differs from the image's");
    }
  } else {
    read.size = mask_size;
    checkImageSize(view, read.size, read.mask_path);
  }
  read.jpeg = hasJpegExtension(read.mask_path);
  if (read.jpeg && coarse_reduction == 1) return read;  // decoded in the second pass only
  if (read.jpeg) {
    const cv::Mat coarse = readMaskReduced(read.mask_path, coarse_reduction);
    if (coarse.size() == reducedSize(read.size, coarse_reduction)) {
      read.coarse = RunLengthMask(coarse);
      return read;
    }
    read.jpeg = false;  // named .jpg but not decoded at scale (not a JPEG): decoded whole below
  }
  const cv::Mat mask = loadMask(read.mask_path);
  if (mask.size() != read.size) {
    throw std::runtime_error(read.mask_path + ": mask size differs from the image's");
  }
  read.full = RunLengthMask(mask);
  if (coarse_reduction > 1) read.coarse = RunLengthMask(reduceMask(mask, coarse_reduction));
  return read;
}

/// The mask at `reduction`, of reducedSize(size, reduction).
RunLengthMask readSecond(const FirstPass& read, int reduction) {
  if (!read.jpeg) {
    return reduction == 1 ? read.full : RunLengthMask(reduceMask(read.full.decode(), reduction));
  }
  cv::Mat mask = readMaskReduced(read.mask_path, reduction);
  // A file named .jpg that is not a JPEG is decoded whole and resized by OpenCV: reduced here.
  if (mask.size() != reducedSize(read.size, reduction)) {
    const cv::Mat full = loadMask(read.mask_path);
    if (full.size() != read.size) {
      throw std::runtime_error(read.mask_path + ": mask size differs from the image's");
    }
    mask = reduceMask(full, reduction);
  }
  return RunLengthMask(mask);
}

/// The LP box of the coarse masks with their cameras reduced alike; empty when there is none (the
/// full-resolution hull then meets the same error and reports it).
std::optional<Box3d> coarseBox(const std::vector<CalibratedView>& views,
                               const std::vector<FirstPass>& read, int reduction,
                               const HullConfig& config) {
  std::vector<PinholeCamera> cameras;
  std::vector<SilhouetteBounds> bounds;
  std::vector<std::string> names;
  try {
    for (size_t i = 0; i < views.size(); ++i) {
      cameras.push_back(views[i].camera.reduced(reduction));
      names.push_back(views[i].name);
      bounds.push_back(viewBounds(names.back(), cameras.back(), read[i].coarse, config));
    }
    requireNoStrayCamera(cameras, names);
    return hullBoundingBox(cameras, bounds, names);
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

}  // namespace

HullInput loadReducedHullInput(const std::string& calibration_path,
                               const std::string& image_directory,
                               const std::string& mask_directory,
                               const std::vector<std::string>& view_names, const HullConfig& config,
                               const std::optional<Box3d>& box, int max_reduction,
                               const std::function<void(size_t read, size_t total)>& on_view_read) {
  if (!isDecodableReduction(max_reduction)) {
    throw std::invalid_argument("loadReducedHullInput: max_reduction must be 1, 2, 4 or 8");
  }
  if (mask_directory.empty()) {
    throw std::invalid_argument("loadReducedHullInput: needs a mask directory");
  }
  const std::vector<CalibratedView> views =
      hullViews(calibration_path, image_directory, view_names);
  const int coarse_reduction = box ? 1 : max_reduction;
  std::vector<FirstPass> read(views.size());
  cv::parallel_for_(cv::Range(0, static_cast<int>(views.size())), [&](const cv::Range& range) {
    for (int i = range.start; i < range.end; ++i) {
      try {
        read[i] = readFirst(image_directory, mask_directory, views[i], coarse_reduction);
      } catch (...) {
        read[i].error = std::current_exception();
      }
    }
  });
  // The first error in view order, as a sequential read meets it.
  for (size_t i = 0; i < views.size(); ++i) {
    if (read[i].error) std::rethrow_exception(read[i].error);
    if (i > 0 && read[i].size != read[0].size) {
      throw std::runtime_error(
          image_directory + "/" + views[i].name + ": image size differs from " +
          views.front().name + "'s (" + std::to_string(read[i].size.width) + "x" +
          std::to_string(read[i].size.height) + ", not " + std::to_string(read[0].size.width) +
          "x" + std::to_string(read[0].size.height) +
          "): one calibration set is for one image size");
    }
  }
  const std::optional<Box3d> carved_in =
      box ? box : (max_reduction > 1 ? coarseBox(views, read, max_reduction, config) : box);
  HullConfig automatic = config;
  automatic.distance_reduction = 0;
  HullInput input;
  input.run_length_masks.resize(views.size());
  input.reductions.assign(views.size(), 1);
  for (size_t i = 0; i < views.size(); ++i) {
    if (carved_in && max_reduction > 1) {
      const int footprint = distanceReduction(views[i].camera, read[i].size, *carved_in, automatic);
      input.reductions[i] = decodableAtMost(std::min(footprint, max_reduction));
    }
  }
  std::vector<std::exception_ptr> errors(views.size());
  std::atomic<size_t> views_read{0};
  cv::parallel_for_(cv::Range(0, static_cast<int>(views.size())), [&](const cv::Range& range) {
    for (int i = range.start; i < range.end; ++i) {
      try {
        input.run_length_masks[i] = readSecond(read[i], input.reductions[i]);
        read[i].full = RunLengthMask();  // each view's full mask freed once reduced
        const size_t done = ++views_read;
        if (on_view_read) on_view_read(done, views.size());
      } catch (...) {
        errors[i] = std::current_exception();
      }
    }
  });
  for (const std::exception_ptr& error : errors) {
    if (error) std::rethrow_exception(error);
  }
  for (size_t i = 0; i < views.size(); ++i) {
    input.names.push_back(views[i].name);
    input.cameras.push_back(views[i].camera.reduced(input.reductions[i]));
    input.image_sizes.push_back(read[i].size);
  }
  return input;
}

int photographReduction(cv::Size image_size, int max_depth, int segment_side_px,
                        int max_reduction) {
  if (!isDecodableReduction(max_reduction)) {
    throw std::invalid_argument("photographReduction: max_reduction must be 1, 2, 4 or 8");
  }
  if (image_size.area() < kMinReducedImagePixels || max_depth < 0 || max_depth > 30) return 1;
  // The finest voxel's footprint when the box spans half the image's longest side.
  const double needed_px =
      std::max(std::ldexp(1.0, max_depth + 1), static_cast<double>(segment_side_px));
  const double longest_px = std::max(image_size.width, image_size.height);
  const int allowed = static_cast<int>(std::clamp(std::floor(longest_px / needed_px), 1.0, 8.0));
  return decodableAtMost(std::min(allowed, max_reduction));
}

HullInput loadReducedPhotoHullInput(
    const std::string& calibration_path, const std::string& image_directory,
    const std::vector<std::string>& view_names, const SilhouetteConfig& recipe,
    const HullConfig& config, int max_reduction, ViewSilhouettes* report,
    const std::function<void(size_t read, size_t total)>& on_view_read) {
  const std::vector<CalibratedView> views =
      hullViews(calibration_path, image_directory, view_names);
  cv::Size size;  // the first image's, from its header; the loader checks the others against it
  if (!views.empty() && !views.front().name.empty()) {
    try {
      size = imageFileSize(image_directory + "/" + views.front().name);
    } catch (const std::runtime_error&) {
      // Missing or unreadable: the loader names it as it names any other view.
    }
  }
  const int reduction =
      photographReduction(size, config.max_depth, recipe.segment_side_px, max_reduction);
  HullInput input;
  input.run_length_masks = loadReducedRunLengthSilhouettes(views, image_directory, "", recipe,
                                                           reduction, report, on_view_read);
  for (const CalibratedView& view : views) {
    input.names.push_back(view.name);
    input.cameras.push_back(view.camera.reduced(reduction));
    input.reductions.push_back(reduction);
    input.image_sizes.push_back(size);
  }
  return input;
}

}  // namespace sift_hull
