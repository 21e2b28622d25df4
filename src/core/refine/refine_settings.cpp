// The settings tables of the refinement's config structs (sift_hull/settings.h) and the checks of
// validate() that derive from them.

#include "sift_hull/refine/free_space.h"
#include "sift_hull/refine/surface_points.h"

namespace sift_hull {

template <>
const SettingTable<SurfacePointConfig>& settingsOf<SurfacePointConfig>() {
  static const SettingTable<SurfacePointConfig> table = [] {
    SettingTable<SurfacePointConfig> t;
    t.add("max_reprojection_px", &SurfacePointConfig::max_reprojection_px, "px",
          "a triangulated match whose reprojection error in either view is larger is left out")
        .above(0.0);
    t.add("confirm_radius_voxels", &SurfacePointConfig::confirm_radius_voxels, "voxels",
          "points of two pairs that share a feature must lie this close to confirm each other")
        .above(0.0);
    return t;
  }();
  return table;
}

template <>
const SettingTable<FreeSpaceConfig>& settingsOf<FreeSpaceConfig>() {
  static const SettingTable<FreeSpaceConfig> table = [] {
    SettingTable<FreeSpaceConfig> t;
    t.add("stop_margin_voxels", &FreeSpaceConfig::stop_margin_voxels, "voxels",
          "a voxel is empty for a view this far in front of its surface of points, plus the "
          "surface's uncertainty")
        .atLeast(0.0);
    t.add("min_views", &FreeSpaceConfig::min_views, "views",
          "views that must see a voxel empty before it is free")
        .atLeast(1);
    t.add("keep_radius_voxels", &FreeSpaceConfig::keep_radius_voxels, "voxels",
          "voxels this close to a surface point are never free")
        .atLeast(0.0);
    t.add("max_edge_fraction", &FreeSpaceConfig::max_edge_fraction, "",
          "longest triangle edge of a view's surface, as a share of the cube's edge")
        .above(0.0, 1.0);
    t.add("max_slant_deg", &FreeSpaceConfig::max_slant_deg, "deg",
          "largest angle between a triangle's normal and the line of sight to it")
        .above(0.0, 90.0);
    t.add("bulge_fraction", &FreeSpaceConfig::bulge_fraction, "",
          "margin added per triangle towards the camera, times its longest edge")
        .atLeast(0.0);
    return t;
  }();
  return table;
}

void validate(const SurfacePointConfig& config) { checkSettings(config, "SurfacePointConfig"); }

void validate(const FreeSpaceConfig& config) { checkSettings(config, "FreeSpaceConfig"); }

}  // namespace sift_hull
