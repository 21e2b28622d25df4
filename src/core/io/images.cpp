#include "sift_hull/io/images.h"

#include <exception>
#include <fstream>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgcodecs.hpp>
#include <stdexcept>

namespace sift_hull {
namespace {

/// cv::imread of a file, or an empty Mat when it is missing or undecodable. Existence is checked
/// first because cv::imread logs its own warning for a missing file.
cv::Mat readImageFile(const std::string& path, int flags) {
  return std::ifstream(path).good() ? cv::imread(path, flags) : cv::Mat();
}

}  // namespace

void checkImageSize(const CalibratedView& view, cv::Size image_size,
                    const std::string& image_path) {
  if (view.width_px == 0 && view.height_px == 0) return;
  // Compared in 64 bits: the calibration's sides are not limited to int.
  if (view.width_px == static_cast<uint64_t>(image_size.width) &&
      view.height_px == static_cast<uint64_t>(image_size.height)) {
    return;
  }
  throw std::runtime_error(view.size_source + ": the camera of view '" + view.name + "' is " +
                           std::to_string(view.width_px) + "x" + std::to_string(view.height_px) +
                           " (WIDTH x HEIGHT) but the image " + image_path + " is " +
                           std::to_string(image_size.width) + "x" +
                           std::to_string(image_size.height));
}

cv::Mat readImage(const std::string& path) {
  cv::Mat image = readImageFile(path, cv::IMREAD_COLOR);
  if (image.empty()) throw std::runtime_error(path + ": image missing or unreadable");
  return image;
}

cv::Mat loadViewImage(const std::string& directory, const CalibratedView& view) {
  const std::string named_at = view.source.empty() ? "" : " (named at " + view.source + ")";
  if (view.name.empty()) {
    throw std::runtime_error((view.source.empty() ? "a view" : view.source) +
                             ": no image name for this view; put one before its numbers");
  }
  const std::string path = directory + "/" + view.name;
  cv::Mat image = readImageFile(path, cv::IMREAD_COLOR);
  if (image.empty()) throw std::runtime_error(path + ": image missing or unreadable" + named_at);
  checkImageSize(view, image.size(), path);
  return image;
}

cv::Mat loadMask(const std::string& path) {
  const cv::Mat raw = readImageFile(path, cv::IMREAD_GRAYSCALE);
  if (raw.empty()) throw std::runtime_error(path + ": mask missing or unreadable");
  cv::Mat mask;
  cv::compare(raw, 0, mask, cv::CMP_GT);
  return mask;
}

namespace {

/// loadSilhouettes, each silhouette converted by `keep` (cv::Mat -> Kept) as soon as it is made.
template <typename Kept, typename Keep>
std::vector<Kept> loadSilhouettesAs(const std::vector<CalibratedView>& views,
                                    const std::string& image_directory,
                                    const std::string& mask_directory,
                                    const SilhouetteConfig& recipe, const Keep& keep) {
  // Each view read and its silhouette made on OpenCV's threads, one image in memory per thread;
  // then the checks in view order, so the first error is the one a sequential read would meet.
  struct Loaded {
    cv::Size image_size, silhouette_size;
    Kept silhouette;
    std::exception_ptr error;
  };
  std::vector<Loaded> loaded(views.size());
  cv::parallel_for_(cv::Range(0, static_cast<int>(views.size())), [&](const cv::Range& range) {
    for (int i = range.start; i < range.end; ++i) {
      try {
        const cv::Mat image = loadViewImage(image_directory, views[i]);
        loaded[i].image_size = image.size();
        const cv::Mat silhouette = mask_directory.empty()
                                       ? silhouetteFromImage(image, recipe)
                                       : loadMask(mask_directory + "/" + views[i].name);
        loaded[i].silhouette_size = silhouette.size();
        loaded[i].silhouette = keep(silhouette);
      } catch (...) {
        loaded[i].error = std::current_exception();
      }
    }
  });
  std::vector<Kept> silhouettes;
  for (size_t i = 0; i < views.size(); ++i) {
    const CalibratedView& view = views[i];
    // A sequential read meets a bad image, then a size other than the first's, then a bad mask.
    if (loaded[i].error && loaded[i].image_size.empty()) std::rethrow_exception(loaded[i].error);
    const cv::Size size = loaded[i].image_size;
    if (i > 0 && size != loaded[0].image_size) {
      throw std::runtime_error(image_directory + "/" + view.name + ": image size differs from " +
                               views.front().name + "'s (" + std::to_string(size.width) + "x" +
                               std::to_string(size.height) + ", not " +
                               std::to_string(loaded[0].image_size.width) + "x" +
                               std::to_string(loaded[0].image_size.height) +
                               "): one calibration set is for one image size");
    }
    if (loaded[i].error) std::rethrow_exception(loaded[i].error);
    if (loaded[i].silhouette_size != size) {
      throw std::runtime_error(mask_directory + "/" + view.name +
                               ": mask size differs from the image's");
    }
    silhouettes.push_back(std::move(loaded[i].silhouette));
  }
  return silhouettes;
}

}  // namespace

std::vector<cv::Mat> loadSilhouettes(const std::vector<CalibratedView>& views,
                                     const std::string& image_directory,
                                     const std::string& mask_directory,
                                     const SilhouetteConfig& recipe) {
  return loadSilhouettesAs<cv::Mat>(views, image_directory, mask_directory, recipe,
                                    [](const cv::Mat& silhouette) { return silhouette; });
}

std::vector<RunLengthMask> loadRunLengthSilhouettes(const std::vector<CalibratedView>& views,
                                                    const std::string& image_directory,
                                                    const std::string& mask_directory,
                                                    const SilhouetteConfig& recipe) {
  return loadSilhouettesAs<RunLengthMask>(
      views, image_directory, mask_directory, recipe,
      [](const cv::Mat& silhouette) { return RunLengthMask(silhouette); });
}

}  // namespace sift_hull
