// The settings tables of the hull's config structs (sift_hull/settings.h) and the checks of
// validate() that derive from them.

#include <Eigen/Core>
#include <stdexcept>
#include <string>
#include <vector>

#include "sift_hull/hull/hull_config.h"
#include "sift_hull/hull/hull_pipeline.h"
#include "sift_hull/hull/hull_stream.h"
#include "sift_hull/hull/reduced_distance_map.h"
#include "sift_hull/hull/silhouette.h"
#include "sift_hull/limits.h"

namespace sift_hull {
namespace {

/// The box as the six numbers [xmin, ymin, zmin, xmax, ymax, zmax]; no box: none.
SettingValue boxNumbers(const HullStreamConfig& config) {
  if (!config.box) return std::vector<double>{};
  const Box3d& box = *config.box;
  return std::vector<double>{box.min_W.x(), box.min_W.y(), box.min_W.z(),
                             box.max_W.x(), box.max_W.y(), box.max_W.z()};
}

/// Sets the box from six numbers, each max above its min (none: automatic); throws
/// std::invalid_argument otherwise.
void setBoxNumbers(HullStreamConfig* config, const SettingValue& value) {
  SettingInfo info;
  info.name = "box";
  info.type = SettingType::kNumberList;
  const std::vector<double> numbers = settingAs<std::vector<double>>(info, value);
  if (numbers.empty()) {
    config->box.reset();
    return;
  }
  if (numbers.size() != 6) throw std::invalid_argument("box must hold six numbers or none");
  Box3d box;
  box.min_W = Eigen::Vector3d(numbers[0], numbers[1], numbers[2]);
  box.max_W = Eigen::Vector3d(numbers[3], numbers[4], numbers[5]);
  if (!(box.size().array() > 0.0).all()) {
    throw std::invalid_argument("box: each max must exceed its min");
  }
  config->box = box;
}

}  // namespace

template <>
const SettingTable<SilhouetteConfig>& settingsOf<SilhouetteConfig>() {
  static const SettingTable<SilhouetteConfig> table = [] {
    SettingTable<SilhouetteConfig> t;
    t.add("silhouette_method", &SilhouetteConfig::silhouette_method, "",
          "how a silhouette is taken from a photo: auto (views, or background where every "
          "view's border is plain and its silhouettes agree across the views as well, to within "
          "0.01), views (all calibrated views together: a prior from the cameras, GrabCut, a "
          "coarse hull; the hull node segments its views together as they come), background "
          "(the border's colours, one image) or threshold (grey level)")
        .oneOf({"auto", "views", "background", "threshold"});
    t.add("threshold", &SilhouetteConfig::threshold, "",
          "the threshold method: grey level in [0, 1] above which a pixel is the object")
        .range(0.0, 1.0);
    t.add("dilate_px", &SilhouetteConfig::dilate_px, "px",
          "radius of the disc the mask is dilated with, before the erosion")
        .range(0, limits::kMaxMorphologyRadiusPx);
    t.add("erode_px", &SilhouetteConfig::erode_px, "px",
          "radius of the disc the mask is then eroded with")
        .range(0, limits::kMaxMorphologyRadiusPx);
    t.add("segment_side_px", &SilhouetteConfig::segment_side_px, "px",
          "the views method: longest image side the segmentation works at")
        .range(64, 4096);
    return t;
  }();
  return table;
}

template <>
const SettingTable<HullConfig>& settingsOf<HullConfig>() {
  static const SettingTable<HullConfig> table = [] {
    SettingTable<HullConfig> t;
    t.add("max_depth", &HullConfig::max_depth, "levels",
          "octree levels below the root cube: the finest cell is the cube's edge / 2^max_depth")
        .range(2, limits::kMaxHullDepth);
    t.add("resolution_m", &HullConfig::resolution_m, "m",
          "finest cell edge (octomap_server's resolution), which then sets the depth; 0: from "
          "max_depth")
        .atLeast(0.0);
    t.add("carve_outside_image", &HullConfig::carve_outside_image, "",
          "views carve everything they see outside their image");
    t.add("distance_slack_px", &HullConfig::distance_slack_px, "px",
          "margin for the sampled distance transform")
        .atLeast(0.0);
    t.add("threads", &HullConfig::threads, "", "carving threads").range(1, limits::kMaxThreads);
    t.add("distance_reduction", &HullConfig::distance_reduction, "px",
          "image pixels per side of a distance-map element: 0 chooses per view, 1 is full "
          "resolution")
        .range(0, kMaxDistanceReduction);
    return t;
  }();
  return table;
}

template <>
const SettingTable<HullStreamConfig>& settingsOf<HullStreamConfig>() {
  static const SettingTable<HullStreamConfig> table = [] {
    SettingTable<HullStreamConfig> t;
    t.nest("", &HullStreamConfig::hull, settingsOf<HullConfig>());
    t.addCustom("box", SettingType::kNumberList, "m",
                "[xmin, ymin, zmin, xmax, ymax, zmax] in the world frame; empty: the box the "
                "first views bound",
                boxNumbers, setBoxNumbers);
    t.add("skip_views", &HullStreamConfig::skip_views, "",
          "names of views left out: file names; in the hull node frame ids, or FRAME@SEC.NSEC "
          "(the stamp's seconds, nanoseconds in 9 digits) for one view of a moving camera");
    t.add("min_view_distance_m", &HullStreamConfig::min_view_distance_m, "m",
          "a view whose camera centre is this close to a view taken, and ...")
        .atLeast(0.0);
    t.add("min_view_angle_deg", &HullStreamConfig::min_view_angle_deg, "deg",
          "... whose optical axis is this close to that view's, is left out; 0 and 0 take every "
          "view")
        .range(0.0, 180.0);
    t.add("max_waiting_views", &HullStreamConfig::max_waiting_views, "views",
          "views waiting for a box; one more refuses the oldest")
        .atLeast(2);
    t.add("max_views", &HullStreamConfig::max_views, "views",
          "views the hull takes; later ones are refused")
        .atLeast(1);
    return t;
  }();
  return table;
}

void validate(const SilhouetteConfig& config) { checkSettings(config, "SilhouetteConfig"); }

void validate(const HullConfig& config) {
  checkSettings(config, "HullConfig");
  limits::requireInRange("HullConfig::padding_px", config.padding_px, 1, limits::kMaxPaddingPx);
}

void validate(const HullStreamConfig& config) {
  validate(config.hull);
  checkSettings(config, "HullStreamConfig");
  if (config.box) HullCube::forConfig(*config.box, config.hull);  // throws for a bad box
}

}  // namespace sift_hull
