// The views' silhouettes, from mask files or segmented from their photographs, at full resolution
// or reduced (sift_hull/io/images.h: loadSilhouettes, loadRunLengthSilhouettes,
// loadReducedRunLengthSilhouettes).

#include <algorithm>
#include <atomic>
#include <cmath>
#include <exception>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "sift_hull/hull/view_silhouettes.h"
#include "sift_hull/io/images.h"
#include "sift_hull/io/reduced_images.h"

namespace sift_hull {
namespace {

/// The recipe for images reduced `reduction` times: its radii, in full-resolution pixels, divided.
SilhouetteConfig reducedRecipe(const SilhouetteConfig& recipe, int reduction) {
  SilhouetteConfig reduced = recipe;
  reduced.dilate_px = static_cast<int>(std::lround(recipe.dilate_px / double(reduction)));
  reduced.erode_px = static_cast<int>(std::lround(recipe.erode_px / double(reduction)));
  return reduced;
}

/// loadSilhouettes, each silhouette converted by `keep` (cv::Mat -> Kept) as soon as it is made,
/// the photographs read `reduction` times reduced (loadReducedViewImage) and the silhouettes made
/// at that size, with the cameras reduced alike.
template <typename Kept, typename Keep>
std::vector<Kept> loadSilhouettesAs(const std::vector<CalibratedView>& views,
                                    const std::string& image_directory,
                                    const std::string& mask_directory,
                                    const SilhouetteConfig& full_recipe, const Keep& keep,
                                    ViewSilhouettes* report, int reduction,
                                    const std::function<void(size_t, size_t)>& on_view_read) {
  if (!isDecodableReduction(reduction) || (reduction > 1 && !mask_directory.empty())) {
    throw std::invalid_argument("loadSilhouettes: photographs reduced 1, 2, 4 or 8 times");
  }
  const SilhouetteConfig recipe = reducedRecipe(full_recipe, reduction);
  bool choose = recipe.silhouette_method == "auto";
  const bool together = mask_directory.empty() && (choose || recipe.silhouette_method == "views") &&
                        views.size() >= 2;
  // Each view read and its silhouette made on OpenCV's threads, one image in memory per thread;
  // then the checks in view order, so the first error is the one a sequential read would meet.
  struct Loaded {
    cv::Size image_size, silhouette_size;  ///< the image's full size; the silhouette's
    Kept silhouette;
    cv::Mat working;  ///< the "views" method: the image at the working size, until all are read
    cv::Mat plain;    ///< the "auto" method: the background method's silhouette, plain borders
    bool pending = false;
    std::exception_ptr error;
  };
  std::vector<Loaded> loaded(views.size());
  std::atomic<size_t> views_read{0};
  cv::parallel_for_(cv::Range(0, static_cast<int>(views.size())), [&](const cv::Range& range) {
    for (int i = range.start; i < range.end; ++i) {
      try {
        cv::Mat silhouette;
        if (mask_directory.empty()) {
          // An image with an alpha channel carries its own silhouette.
          const ViewImage image =
              loadReducedViewImage(image_directory, views[i], reduction, &loaded[i].image_size);
          if (!image.alpha_mask.empty()) {
            silhouette = image.alpha_mask;
          } else if (together) {
            cv::resize(image.bgr, loaded[i].working,
                       workingSize(image.bgr.size(), recipe.segment_side_px), 0, 0, cv::INTER_AREA);
            if (choose) loaded[i].plain = plainBackgroundSilhouette(image.bgr, recipe);
            loaded[i].pending = true;
          } else {
            silhouette = silhouetteFromImage(image.bgr, recipe);
          }
        } else {
          loaded[i].image_size = loadViewImage(image_directory, views[i]).size();
          silhouette = loadMask(maskPath(mask_directory, views[i].name));
        }
        if (!loaded[i].pending) {
          loaded[i].silhouette_size = silhouette.size();
          loaded[i].silhouette = keep(silhouette);
        }
        const size_t done = ++views_read;
        if (on_view_read) on_view_read(done, views.size());
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
    if (loaded[i].silhouette_size != reducedSize(size, reduction)) {
      throw std::runtime_error(mask_directory + "/" + view.name +
                               ": mask size differs from the image's");
    }
    silhouettes.push_back(std::move(loaded[i].silhouette));
  }
  const bool any_pending =
      std::any_of(loaded.begin(), loaded.end(), [](const Loaded& l) { return l.pending; });
  if (!any_pending) return silhouettes;
  // The "views" method: every view's working-size image at once, with the cameras.
  const cv::Size reduced_size = reducedSize(loaded[0].image_size, reduction);
  const auto reread = [&](size_t i) {
    cv::Size full;
    return loadReducedViewImage(image_directory, views[i], reduction, &full).bgr;
  };
  std::vector<cv::Mat> working;
  std::vector<PinholeCamera> cameras;
  std::vector<std::string> names;
  const cv::Size size = workingSize(reduced_size, recipe.segment_side_px);
  for (size_t i = 0; i < views.size(); ++i) {
    if (loaded[i].working.empty()) {  // a view with its own alpha mask: read again, small
      cv::resize(reread(i), loaded[i].working, size, 0, 0, cv::INTER_AREA);
    }
    working.push_back(std::move(loaded[i].working));
    cameras.push_back(views[i].camera.reduced(reduction));
    names.push_back(views[i].name);
  }
  ViewSilhouettes found;
  try {
    found = silhouettesFromViews(working, cameras, names, reduced_size, recipe);
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
      found.masks.push_back(!loaded[i].pending || !loaded[i].plain.empty()
                                ? loaded[i].plain
                                : silhouetteFromImage(reread(i), background));
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
  return loadSilhouettesAs<cv::Mat>(views, image_directory, mask_directory, recipe,
                                    [](const cv::Mat& silhouette) { return silhouette; }, report, 1,
                                    {});
}

std::vector<RunLengthMask> loadRunLengthSilhouettes(const std::vector<CalibratedView>& views,
                                                    const std::string& image_directory,
                                                    const std::string& mask_directory,
                                                    const SilhouetteConfig& recipe,
                                                    ViewSilhouettes* report) {
  return loadReducedRunLengthSilhouettes(views, image_directory, mask_directory, recipe, 1, report,
                                         {});
}

std::vector<RunLengthMask> loadReducedRunLengthSilhouettes(
    const std::vector<CalibratedView>& views, const std::string& image_directory,
    const std::string& mask_directory, const SilhouetteConfig& recipe, int reduction,
    ViewSilhouettes* report, const std::function<void(size_t read, size_t total)>& on_view_read) {
  return loadSilhouettesAs<RunLengthMask>(
      views, image_directory, mask_directory, recipe,
      [](const cv::Mat& silhouette) { return RunLengthMask(silhouette); }, report, reduction,
      on_view_read);
}

}  // namespace sift_hull
