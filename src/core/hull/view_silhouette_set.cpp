// The views' silhouettes for views that arrive one at a time
// (sift_hull/hull/view_silhouette_set.h).

#include "sift_hull/hull/view_silhouette_set.h"

#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace sift_hull {

ViewSilhouetteSet::ViewSilhouetteSet(SilhouetteConfig config, size_t max_views)
    : config_(std::move(config)), max_views_(max_views) {
  validate(config_);
  if (max_views_ < 2) throw std::invalid_argument("ViewSilhouetteSet: max_views must be >= 2");
}

cv::Mat ViewSilhouetteSet::add(const std::string& name, const cv::Mat& image,
                               const PinholeCamera& camera) {
  if (image.empty() || image.depth() != CV_8U || (image.channels() != 1 && image.channels() != 3)) {
    throw std::invalid_argument("view '" + name + "': an 8-bit grey or BGR photograph is needed");
  }
  if (!views_.empty() && image.size() != full_size_) {
    throw std::invalid_argument(
        "view '" + name + "': its photograph is " + std::to_string(image.cols) + "x" +
        std::to_string(image.rows) + ", the first view's " + std::to_string(full_size_.width) +
        "x" + std::to_string(full_size_.height) + ": the views segmented together share one size");
  }
  SilhouetteConfig background = config_;
  background.silhouette_method = "background";
  // The plain border's colour model when it applies (auto's candidate), else the background
  // method with its GrabCut; one colour model either way.
  bool plain = false;
  cv::Mat mask = silhouetteFromImage(image, background, &plain);
  if (views_.size() >= max_views_) {
    ++not_kept_;
    return mask;
  }
  full_size_ = image.size();
  Kept kept{name, camera, cv::Mat(), RunLengthMask(mask), plain};
  cv::Mat bgr = image;
  if (image.channels() == 1) cv::cvtColor(image, bgr, cv::COLOR_GRAY2BGR);
  cv::resize(bgr, kept.working, workingSize(image.size(), config_.segment_side_px), 0, 0,
             cv::INTER_AREA);
  views_.push_back(std::move(kept));
  return mask;
}

bool ViewSilhouetteSet::segmentDue(bool any_new) const {
  if (views_.size() < kFirstViews) return false;
  if (any_new) return views_.size() > segmented_at_;
  return segmented_at_ == 0 ||
         static_cast<double>(views_.size()) >= kGrowth * static_cast<double>(segmented_at_);
}

ViewSilhouetteSet::Segmented ViewSilhouetteSet::segment() {
  segmented_at_ = views_.size();
  Segmented out;
  std::vector<cv::Mat> working;
  for (const Kept& view : views_) {
    out.names.push_back(view.name);
    out.cameras.push_back(view.camera);
    working.push_back(view.working);
  }
  out.report = silhouettesFromViews(working, out.cameras, out.names, full_size_, config_);
  if (config_.silhouette_method == "auto") {
    std::vector<cv::Mat> plain;
    for (const Kept& view : views_) {
      plain.push_back(view.plain_border ? view.background.decode() : cv::Mat());
    }
    chooseBackgroundWhereItAgrees(&out.report, std::move(plain), out.names, out.cameras, config_);
  }
  out.masks = std::move(out.report.masks);
  out.report.masks.clear();
  return out;
}

size_t ViewSilhouetteSet::memoryBytes() const {
  size_t bytes = 0;
  for (const Kept& view : views_) {
    bytes += view.working.total() * view.working.elemSize() + view.background.memoryBytes();
  }
  return bytes;
}

void ViewSilhouetteSet::clear() {
  views_.clear();
  segmented_at_ = 0;
  not_kept_ = 0;
}

}  // namespace sift_hull
