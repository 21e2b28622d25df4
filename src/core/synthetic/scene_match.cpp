// Whether views are those of a rendered scene, before the scene serves as their ground truth.

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <opencv2/core.hpp>
#include <sstream>
#include <stdexcept>

#include "sift_hull/io/images.h"
#include "sift_hull/synthetic/scene.h"

namespace sift_hull {
namespace {

/// A silhouette that overlaps the scene's mask less than this (intersection over union) is not a
/// view of the scene.
constexpr double kMinMaskIoU = 0.5;

std::string number(double value) {
  std::ostringstream text;
  text << std::setprecision(3) << value;
  return text.str();
}

/// The largest distance, in pixels, between where `a` and `b` see the solid's bounding sphere
/// (its centre and its six extreme points on the axes); infinity when either sees one behind it.
double projectionGap(const PinholeCamera& a, const PinholeCamera& b, const Shape& shape) {
  const Eigen::Vector3d centre = shape.boundingCentre();
  const double radius = shape.boundingRadius();
  double gap = 0.0;
  for (int k = 0; k < 7; ++k) {
    Eigen::Vector3d X = centre;
    if (k > 0) X((k - 1) / 2) += (k % 2 == 0 ? -radius : radius);
    if (!(a.depth(X) > 0.0) || !(b.depth(X) > 0.0)) return HUGE_VAL;
    const double d = (a.project(X) - b.project(X)).norm();
    gap = std::isfinite(d) ? std::max(gap, d) : HUGE_VAL;
  }
  return gap;
}

double maskIoU(const cv::Mat& a, const cv::Mat& b) {
  if (a.size() != b.size()) return 0.0;
  const double both = cv::countNonZero((a != 0) & (b != 0));
  const double either = cv::countNonZero((a != 0) | (b != 0));
  return either > 0.0 ? both / either : 1.0;
}

const CalibratedView* sceneView(const SceneData& scene, const std::string& name) {
  for (const CalibratedView& view : scene.views) {
    if (view.name == name) return &view;
  }
  return nullptr;
}

}  // namespace

void requireViewsOfScene(const SceneData& scene, const std::string& scene_directory,
                         const HullInput& input, const std::string& views_source) {
  const std::string refusal = "--gt-scene " + scene_directory +
                              " is not the scene of the views of " + views_source + ": view '";
  const Shape shape = Shape::byName(scene.config.shape);
  const double diagonal_px = std::hypot(scene.config.width_px, scene.config.height_px);
  const double max_gap_px = std::max(2.0, 0.01 * diagonal_px);
  for (size_t i = 0; i < input.names.size(); ++i) {
    const std::string& name = input.names[i];
    const CalibratedView* truth = sceneView(scene, name);
    if (truth == nullptr) throw std::runtime_error(refusal + name + "' is not one of its views");
    const double gap = projectionGap(input.cameras[i], truth->camera, shape);
    if (!(gap <= max_gap_px)) {
      throw std::runtime_error(refusal + name + "' sees the scene's solid " + number(gap) +
                               " px from where the scene's camera does (more than " +
                               number(max_gap_px) + " px): another scene?");
    }
    if (input.viewCount() == 0) continue;  // cameras only
    const cv::Mat mask = input.mask(i);
    const double iou = maskIoU(mask, loadMask(scene_directory + "/" + kMaskDirectory + "/" + name));
    if (!(iou >= kMinMaskIoU)) {
      throw std::runtime_error(refusal + name + "': its silhouette overlaps the scene's mask by " +
                               number(iou) + " (intersection over union, at least " +
                               number(kMinMaskIoU) + " expected): another scene?");
    }
  }
}

}  // namespace sift_hull
