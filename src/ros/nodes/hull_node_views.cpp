// The hull node's views (on the worker): each message made a view, and with ~from_image and the
// views or auto method, the photographs segmented together (ViewSilhouetteSet) and the hull
// carved again from their silhouettes.

#include <algorithm>

#include "lib/conversions.h"
#include "nodes/hull_node.h"
#include "sift_hull/hull/silhouette.h"

namespace sift_hull {
namespace {

/// Photographs kept to segment together (about 0.4 MB each at the working size); later views keep
/// the background method's silhouette.
constexpr size_t kMaxViewsTogether = 200;
constexpr double kThrottle_s = 5.0;

}  // namespace

void HullNode::startSegmentingTogether() {
  const std::string& method = config_.recipe.silhouette_method;
  if (config_.from_image && (method == "views" || method == "auto")) {
    together_ = std::make_unique<ViewSilhouetteSet>(config_.recipe, kMaxViewsTogether);
  }
}

bool HullNode::viewOf(const Posed& posed, View* view) {
  const sensor_msgs::Image& silhouette = *posed.silhouette;
  const std::string& name = silhouette.header.frame_id;
  std::string why_not;
  cv::Mat image = config_.from_image ? ros_conversions::eightBitImage(posed.silhouette, &why_not)
                                     : ros_conversions::maskFromImage(silhouette, &why_not);
  if (image.empty() || !ros_conversions::cameraFromInfo(
                           *posed.info, posed.T_W_C, cv::Size(silhouette.width, silhouette.height),
                           &view->camera, &why_not, config_.rectified)) {
    problem("hull: view '" + name + "' ignored: ", why_not);
    return false;
  }
  view->mask = image;
  if (config_.from_image) {
    // An image with a varying alpha channel (rgba8, bgra8) carries its own silhouette.
    const cv::Mat alpha = ros_conversions::alphaMask(posed.silhouette);
    try {
      view->mask = !alpha.empty() ? alpha
                   : together_    ? together_->add(name, image, view->camera)
                                  : silhouetteFromImage(image, config_.recipe);
    } catch (const std::exception& e) {
      problem("hull: view '" + name + "' ignored: ", e.what());
      return false;
    }
  }
  view->name = name;
  view->stamp = silhouette.header.stamp;
  return true;
}

bool HullNode::segmentTogether() {
  const ros::WallTime start = ros::WallTime::now();
  ViewSilhouetteSet::Segmented segmented;
  try {
    segmented = together_->segment();
  } catch (const std::exception& e) {
    ++segmentations_failed_;
    problem("hull: the views' silhouettes could not be made together (each view keeps its own): ",
            e.what());
    return false;
  }
  // The hull anew from every kept view's new silhouette; the views beyond those kept, and the
  // surface points, are carved again too (the points at the next refinement).
  hull_.restartViews();
  for (size_t i = 0; i < segmented.names.size(); ++i) {
    try {
      hull_.add(segmented.names[i], segmented.cameras[i], segmented.masks[i]);
    } catch (const std::exception& e) {
      problem("hull: view '" + segmented.names[i] + "' ignored: ", e.what());
    }
  }
  hull_.takeRefusals();  // each was reported when its view first came
  counts_.waiting = hull_.stream().waitingViews();
  unpublished_stamp_ = newest_view_stamp_;
  const ViewSilhouettes& report = segmented.report;
  for (const std::string& warning : report.warnings) {
    ROS_WARN_THROTTLE(kThrottle_s, "hull: %s", warning.c_str());
  }
  ++segmentations_;
  last_agreement_ = report.method == "background" ? report.background_agreement : report.agreement;
  last_segmentation_ms_ = (ros::WallTime::now() - start).toSec() * 1e3;
  {
    std::lock_guard<std::mutex> lock(segmentation_mutex_);
    last_segmentation_method_ = report.method;
  }
  ROS_INFO("hull: %zu views segmented together (%s method, agreement %.3f) in %.1f s",
           segmented.names.size(), report.method.c_str(), last_agreement_.load(),
           last_segmentation_ms_.load() / 1e3);
  return true;
}

void HullNode::reportSegmentation(diagnostic_updater::DiagnosticStatusWrapper& status) {
  status.add("segmentations together", segmentations_.load());
  status.add("segmentations failed", segmentations_failed_.load());
  status.add("last segmentation ms", last_segmentation_ms_.load());
  status.add("last segmentation agreement", last_agreement_.load());
  std::lock_guard<std::mutex> lock(segmentation_mutex_);
  status.add("last segmentation method", last_segmentation_method_);
}

}  // namespace sift_hull
