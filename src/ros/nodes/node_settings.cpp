// The settings tables of the nodes' own config structs (sift_hull/settings.h). No ROS here: the
// parameter reader, the reconfigure mapping, config/*.yaml and docs/NODES.md derive from them.

#include "nodes/hull_node_config.h"
#include "nodes/matcher_node_config.h"
#include "sift_hull/limits.h"

namespace sift_hull {

template <>
const SettingTable<HullNodeConfig>& settingsOf<HullNodeConfig>() {
  static const SettingTable<HullNodeConfig> table = [] {
    SettingTable<HullNodeConfig> t;
    t.add("world_frame", &HullNodeConfig::world_frame, "",
          "frame the hull is built and published in (octomap_server's frame_id)");
    t.add("queue_size", &HullNodeConfig::queue_size, "views",
          "silhouettes waiting for camera_info or their pose in tf, and views waiting to be "
          "carved; one more drops the oldest")
        .atLeast(1);
    t.add("pose_timeout_s", &HullNodeConfig::pose_timeout_s, "s",
          "a silhouette paired with its camera_info whose pose is not in tf by then is dropped; "
          "<= 0: no limit");
    t.add("from_image", &HullNodeConfig::from_image, "",
          "subscribe `image` and take each silhouette by the recipe (silhouette_method)");
    t.add("rectified", &HullNodeConfig::rectified, "",
          "silhouettes of image_rect (image_proc): cameras from P and R, whatever D says");
    t.add("diagnostic_period", &HullNodeConfig::diagnostic_period, "s",
          "wall time between /diagnostics reports")
        .above(0.0);
    t.nest("", &HullNodeConfig::recipe, settingsOf<SilhouetteConfig>());
    t.add("refine_period_s", &HullNodeConfig::refine_period_s, "s",
          "wall time between refinements with new surface points")
        .above(0.0);
    t.nest("", &HullNodeConfig::carving, settingsOf<PointCarvingConfig>());
    t.add("photo_carve", &HullNodeConfig::photo_carve, "",
          "take the photographs beside the silhouettes (`image`; from_image: the images), carve "
          "the hull by their depth maps in the background and colour the clouds");
    t.add("photo_color_octomap", &HullNodeConfig::photo_color_octomap, "",
          "photo_carve: octomap_full is OctoMap's ColorOcTree");
    t.nest("", &HullNodeConfig::photo, settingsOf<PhotoStreamConfig>());
    return t;
  }();
  return table;
}

template <>
const SettingTable<HullNodeSettings>& settingsOf<HullNodeSettings>() {
  static const SettingTable<HullNodeSettings> table = [] {
    SettingTable<HullNodeSettings> t;
    t.nest("", &HullNodeSettings::node, settingsOf<HullNodeConfig>());
    t.nest("", &HullNodeSettings::stream, settingsOf<HullStreamConfig>());
    return t;
  }();
  return table;
}

template <>
const SettingTable<MatcherNodeConfig>& settingsOf<MatcherNodeConfig>() {
  static const SettingTable<MatcherNodeConfig> table = [] {
    SettingTable<MatcherNodeConfig> t;
    t.add("filters", &MatcherNodeConfig::filters, "",
          "filters run on each pair, by name: best, vote_ransac, guided, lsc, local_gsc, gsc, "
          "ratio, ransac, magsac, gms, epipolar (calibrated), or a chain \"a+b\"");
    t.add("queue_size", &MatcherNodeConfig::queue_size, "images",
          "images waiting for their partner")
        .atLeast(1);
    t.add("max_waiting_pairs", &MatcherNodeConfig::max_waiting_pairs, "pairs",
          "pairs waiting for a worker; one more drops the oldest (counted in /diagnostics)")
        .atLeast(1);
    t.add("workers", &MatcherNodeConfig::workers, "",
          "threads matching pairs side by side (more than one: output may leave stamp order)")
        .range(1, limits::kMaxThreads);
    t.add("approximate_sync", &MatcherNodeConfig::approximate_sync, "",
          "pair images by nearest stamps instead of equal ones");
    t.add("calibrated", &MatcherNodeConfig::calibrated, "",
          "also take the camera_info beside each image and the right camera's pose (tf, or the "
          "right P's baseline in one frame): the epipolar filter and `points`");
    t.add("rectified", &MatcherNodeConfig::rectified, "",
          "the images are image_rect (image_proc): cameras from P and R, whatever D says");
    t.add("frame_to_frame", &MatcherNodeConfig::frame_to_frame, "",
          "one `image` topic, each frame matched with the one before it (with calibrated: with "
          "the keyframe, once the camera has moved min_baseline_m)");
    t.add("world_frame", &MatcherNodeConfig::world_frame, "",
          "calibrated frame to frame: frame the camera poses are looked up in (tf)");
    t.add("pose_timeout_s", &MatcherNodeConfig::pose_timeout_s, "s",
          "calibrated frame to frame: a frame whose pose is not in tf by then is dropped; <= 0: "
          "no limit");
    t.add("min_baseline_m", &MatcherNodeConfig::min_baseline_m, "m",
          "calibrated frame to frame: frames whose camera centre is this close to the keyframe's "
          "are skipped; the first further away is matched with it and becomes the keyframe")
        .atLeast(0.0);
    t.add("max_rotation_deg", &MatcherNodeConfig::max_rotation_deg, "deg",
          "calibrated frame to frame: a frame turned further from the keyframe is not matched "
          "and becomes the keyframe")
        .range(0.0, 180.0);
    t.add("image_transport", &MatcherNodeConfig::image_transport, "",
          "raw, compressed (decoded here when no plugin provides it), or another image_transport "
          "plugin");
    t.add("diagnostic_period", &MatcherNodeConfig::diagnostic_period, "s",
          "wall time between /diagnostics reports")
        .above(0.0);
    return t;
  }();
  return table;
}

template <>
const SettingTable<MatcherSettings>& settingsOf<MatcherSettings>() {
  static const SettingTable<MatcherSettings> table = [] {
    SettingTable<MatcherSettings> t;
    t.nest("", &MatcherSettings::node, settingsOf<MatcherNodeConfig>());
    t.nest("", &MatcherSettings::sift, settingsOf<SiftConfig>());
    t.nest("", &MatcherSettings::matching, settingsOf<MatchConfig>());
    t.nest("", &MatcherSettings::filters, settingsOf<FilterConfigs>());
    return t;
  }();
  return table;
}

}  // namespace sift_hull
