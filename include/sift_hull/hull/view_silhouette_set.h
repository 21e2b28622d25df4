#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "sift_hull/geometry/camera.h"
#include "sift_hull/hull/run_length_mask.h"
#include "sift_hull/hull/silhouette.h"
#include "sift_hull/hull/view_silhouettes.h"

namespace sift_hull {

/// The "views" and "auto" silhouette methods for views that arrive one at a time, as the hull
/// node's `~from_image` has them. Each view's photograph is kept at the working size
/// (SilhouetteConfig::segment_side_px), with the background method's silhouette run-length
/// encoded (auto's other candidate). A new view's silhouette for now is the background
/// method's; the whole set is segmented together (silhouettesFromViews, then auto's choice)
/// once it has kFirstViews views and each time it has grown by kGrowth since, and again on
/// request when views came since (segmentDue). At most `max_views` views are kept; later ones
/// keep the background method's silhouette.
class ViewSilhouetteSet {
 public:
  static constexpr size_t kFirstViews = 4;
  static constexpr double kGrowth = 1.5;

  /// Throws std::invalid_argument for an invalid config or max_views < 2.
  ViewSilhouetteSet(SilhouetteConfig config, size_t max_views);

  /// Adds a view: an 8-bit grey or BGR photograph at the size its camera is for. Returns its
  /// silhouette for now (the background method's). Throws std::invalid_argument for an empty
  /// image, or one of another size than the first view's.
  cv::Mat add(const std::string& name, const cv::Mat& image, const PinholeCamera& camera);

  /// Whether the set has grown by kGrowth since its last segmentation (kFirstViews views at the
  /// first); with `any_new`, whether any view came since (and it has kFirstViews views).
  bool segmentDue(bool any_new) const;

  struct Segmented {
    std::vector<std::string> names;
    std::vector<PinholeCamera> cameras;
    std::vector<cv::Mat> masks;  ///< CV_8UC1 at the photographs' size
    ViewSilhouettes report;      ///< without its masks
  };
  /// Every kept view's silhouette, segmented together. Throws std::runtime_error as
  /// silhouettesFromViews does (the set is then due again only once it has grown).
  Segmented segment();

  size_t size() const { return views_.size(); }
  /// Views that came after max_views were kept.
  size_t notKept() const { return not_kept_; }
  /// Memory of the kept photographs and silhouettes.
  size_t memoryBytes() const;
  void clear();

 private:
  struct Kept {
    std::string name;
    PinholeCamera camera;
    cv::Mat working;            ///< BGR at the working size
    RunLengthMask background;   ///< the background method's silhouette at full size
    bool plain_border = false;  ///< its border is plain (auto's candidate)
  };
  SilhouetteConfig config_;
  size_t max_views_;
  cv::Size full_size_;
  std::vector<Kept> views_;
  size_t segmented_at_ = 0;  ///< views at the last segmentation (or attempt)
  size_t not_kept_ = 0;
};

}  // namespace sift_hull
