#include "sift_hull/io/images.h"

#include <dirent.h>

#include <algorithm>
#include <cctype>
#include <exception>
#include <fstream>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "sift_hull/hull/view_silhouettes.h"
#include "sift_hull/io/reduced_images.h"

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

cv::Mat readImage(const std::string& path, int imread_flags) {
  cv::Mat image = readImageFile(path, imread_flags);
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

namespace {

/// True for the file types whose images may carry an alpha channel.
bool mayHaveAlpha(const std::string& path) {
  const std::string::size_type dot = path.find_last_of('.');
  if (dot == std::string::npos) return false;
  std::string extension = path.substr(dot + 1);
  for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return extension == "png" || extension == "tif" || extension == "tiff" || extension == "webp";
}

/// An image as cv::IMREAD_COLOR gives it (BGR, 8 bits) from an IMREAD_UNCHANGED decoding.
cv::Mat asBgr8(const cv::Mat& raw) {
  cv::Mat eight = raw;
  if (raw.depth() == CV_16U) {
    raw.convertTo(eight, CV_8U, 1.0 / 257.0);
  } else if (raw.depth() != CV_8U) {
    raw.convertTo(eight, CV_8U, 255.0);
  }
  cv::Mat bgr;
  if (eight.channels() == 1) {
    cv::cvtColor(eight, bgr, cv::COLOR_GRAY2BGR);
  } else if (eight.channels() == 4) {
    cv::cvtColor(eight, bgr, cv::COLOR_BGRA2BGR);
  } else {
    bgr = eight;
  }
  return bgr;
}

}  // namespace

ViewImage loadViewImageWithAlpha(const std::string& directory, const CalibratedView& view) {
  const std::string path = directory + "/" + view.name;
  if (view.name.empty() || !mayHaveAlpha(path)) return {loadViewImage(directory, view), cv::Mat()};
  const cv::Mat raw = readImageFile(path, cv::IMREAD_UNCHANGED);
  if (raw.empty() || (raw.channels() != 1 && raw.channels() != 3 && raw.channels() != 4)) {
    return {loadViewImage(directory, view), cv::Mat()};  // its errors, or OpenCV's own conversion
  }
  checkImageSize(view, raw.size(), path);
  ViewImage image{asBgr8(raw), cv::Mat()};
  if (raw.channels() == 4) {
    cv::Mat alpha;
    cv::extractChannel(raw, alpha, 3);
    double low = 0.0, high = 0.0;
    cv::minMaxLoc(alpha, &low, &high);
    // A constant alpha says nothing about the object; half of full scale separates the two.
    const double full = raw.depth() == CV_16U ? 65535.0 : raw.depth() == CV_8U ? 255.0 : 1.0;
    if (low < high) cv::compare(alpha, 0.5 * full, image.alpha_mask, cv::CMP_GE);
  }
  return image;
}

std::string maskPath(const std::string& mask_directory, const std::string& image_name) {
  const std::string same = mask_directory + "/" + image_name;
  if (std::ifstream(same).good()) return same;
  // The same number under another width or extension: image/000012.png against mask/012.png.
  const std::string::size_type slash = image_name.find_last_of('/');
  std::string stem = image_name.substr(slash == std::string::npos ? 0 : slash + 1);
  stem = stem.substr(0, stem.find_last_of('.'));
  if (stem.empty() || stem.size() > 18 ||
      stem.find_first_not_of("0123456789") != std::string::npos) {
    return same;
  }
  const unsigned long long number = std::stoull(stem);
  std::vector<std::string> candidates;
  if (DIR* dir = opendir(mask_directory.c_str())) {
    while (const dirent* entry = readdir(dir)) {
      std::string name = entry->d_name;
      const std::string::size_type dot = name.find_last_of('.');
      const std::string digits = name.substr(0, dot);
      if (digits.empty() || digits.size() > 18 ||
          digits.find_first_not_of("0123456789") != std::string::npos) {
        continue;
      }
      if (std::stoull(digits) == number) candidates.push_back(name);
    }
    closedir(dir);
  }
  if (candidates.size() != 1) return same;  // none, or ambiguous: the error names the plain path
  return mask_directory + "/" + candidates.front();
}

cv::Mat loadMask(const std::string& path) {
  const cv::Mat raw = readImageFile(path, cv::IMREAD_GRAYSCALE);
  if (raw.empty()) throw std::runtime_error(path + ": mask missing or unreadable");
  return maskInside(raw);
}

namespace {

/// loadSilhouettes, each silhouette converted by `keep` (cv::Mat -> Kept) as soon as it is made.
template <typename Kept, typename Keep>
std::vector<Kept> loadSilhouettesAs(const std::vector<CalibratedView>& views,
                                    const std::string& image_directory,
                                    const std::string& mask_directory,
                                    const SilhouetteConfig& recipe, const Keep& keep,
                                    ViewSilhouettes* report) {
  bool choose = recipe.silhouette_method == "auto";
  const bool together = mask_directory.empty() && (choose || recipe.silhouette_method == "views") &&
                        views.size() >= 2;
  // Each view read and its silhouette made on OpenCV's threads, one image in memory per thread;
  // then the checks in view order, so the first error is the one a sequential read would meet.
  struct Loaded {
    cv::Size image_size, silhouette_size;
    Kept silhouette;
    cv::Mat working;  ///< the "views" method: the image at the working size, until all are read
    cv::Mat plain;    ///< the "auto" method: the background method's silhouette, plain borders
    bool pending = false;
    std::exception_ptr error;
  };
  std::vector<Loaded> loaded(views.size());
  cv::parallel_for_(cv::Range(0, static_cast<int>(views.size())), [&](const cv::Range& range) {
    for (int i = range.start; i < range.end; ++i) {
      try {
        cv::Mat silhouette;
        if (mask_directory.empty()) {
          // An image with an alpha channel carries its own silhouette.
          const ViewImage image = loadViewImageWithAlpha(image_directory, views[i]);
          loaded[i].image_size = image.bgr.size();
          if (!image.alpha_mask.empty()) {
            silhouette = image.alpha_mask;
          } else if (together) {
            cv::resize(image.bgr, loaded[i].working,
                       workingSize(image.bgr.size(), recipe.segment_side_px), 0, 0, cv::INTER_AREA);
            if (choose) loaded[i].plain = plainBackgroundSilhouette(image.bgr, recipe);
            loaded[i].pending = true;
            continue;
          } else {
            silhouette = silhouetteFromImage(image.bgr, recipe);
          }
        } else {
          loaded[i].image_size = loadViewImage(image_directory, views[i]).size();
          silhouette = loadMask(maskPath(mask_directory, views[i].name));
        }
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
    if (loaded[i].pending) {
      silhouettes.emplace_back();
      continue;
    }
    if (loaded[i].silhouette_size != size) {
      throw std::runtime_error(mask_directory + "/" + view.name +
                               ": mask size differs from the image's");
    }
    silhouettes.push_back(std::move(loaded[i].silhouette));
  }
  const bool any_pending =
      std::any_of(loaded.begin(), loaded.end(), [](const Loaded& l) { return l.pending; });
  if (!any_pending) return silhouettes;
  // The "views" method: every view's working-size image at once, with the cameras.
  std::vector<cv::Mat> working;
  std::vector<PinholeCamera> cameras;
  std::vector<std::string> names;
  const cv::Size size = workingSize(loaded[0].image_size, recipe.segment_side_px);
  for (size_t i = 0; i < views.size(); ++i) {
    if (loaded[i].working.empty()) {  // a view with its own alpha mask: read again, small
      cv::resize(loadViewImage(image_directory, views[i]), loaded[i].working, size, 0, 0,
                 cv::INTER_AREA);
    }
    working.push_back(std::move(loaded[i].working));
    cameras.push_back(views[i].camera);
    names.push_back(views[i].name);
  }
  ViewSilhouettes found;
  try {
    found = silhouettesFromViews(working, cameras, names, loaded[0].image_size, recipe);
  } catch (const std::runtime_error& e) {
    if (!choose) throw;
    // auto: each view's own silhouette by the background method, as for one image alone.
    found = {};
    found.method = "background";
    found.background_reason = std::string("the views method failed: ") + e.what();
    found.warnings.push_back(found.background_reason + "; each view's own silhouette is used");
    SilhouetteConfig background = recipe;
    background.silhouette_method = "background";
    for (size_t i = 0; i < views.size(); ++i) {
      found.masks.push_back(
          !loaded[i].pending || !loaded[i].plain.empty()
              ? loaded[i].plain
              : silhouetteFromImage(loadViewImage(image_directory, views[i]), background));
    }
    choose = false;
  }
  if (choose) {
    std::vector<cv::Mat> plain;
    for (Loaded& l : loaded) plain.push_back(l.pending ? std::move(l.plain) : cv::Mat());
    chooseBackgroundWhereItAgrees(&found, std::move(plain), names, cameras, recipe);
  }
  for (size_t i = 0; i < views.size(); ++i) {
    if (loaded[i].pending) silhouettes[i] = keep(found.masks[i]);
  }
  if (report != nullptr) {
    found.masks.clear();
    *report = std::move(found);
  }
  return silhouettes;
}

}  // namespace

std::vector<cv::Mat> loadSilhouettes(const std::vector<CalibratedView>& views,
                                     const std::string& image_directory,
                                     const std::string& mask_directory,
                                     const SilhouetteConfig& recipe, ViewSilhouettes* report) {
  return loadSilhouettesAs<cv::Mat>(
      views, image_directory, mask_directory, recipe,
      [](const cv::Mat& silhouette) { return silhouette; }, report);
}

std::vector<RunLengthMask> loadRunLengthSilhouettes(const std::vector<CalibratedView>& views,
                                                    const std::string& image_directory,
                                                    const std::string& mask_directory,
                                                    const SilhouetteConfig& recipe,
                                                    ViewSilhouettes* report) {
  return loadSilhouettesAs<RunLengthMask>(
      views, image_directory, mask_directory, recipe,
      [](const cv::Mat& silhouette) { return RunLengthMask(silhouette); }, report);
}

}  // namespace sift_hull
