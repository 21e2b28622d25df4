#pragma once

#include <octomap/ColorOcTree.h>
#include <octomap/OcTree.h>
#include <ros/ros.h>
#include <sensor_msgs/PointCloud2.h>
#include <std_msgs/Header.h>
#include <visualization_msgs/Marker.h>

#include <atomic>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "sift_hull/Octomap.h"
#include "sift_hull/hull/hull_octomap.h"
#include "sift_hull/hull/hull_stream.h"
#include "sift_hull/hull/mesh.h"

namespace sift_hull {

/// The hull node's outputs: octomap_server's topics (octomap_binary, octomap_full,
/// octomap_point_cloud_centers and occupied_cells, occupied_cells_vis_array,
/// free_cells_vis_array), the mesh and the carving box, all latched, published through one table
/// of {topic, lazy, builder for the hull, builder for no hull}; and the snapshot the map services
/// answer from, made with each publication.
///
/// Threads: publish(), send() and the cached tree and mesh belong to the thread that owns the hull
/// (the node's worker); a new subscriber of a lazy output is served through `post`, on that
/// thread. The snapshots may be read from any thread.
class HullOutputs {
 public:
  /// Runs a task on the hull's thread (false: it could not be queued).
  using Post = std::function<bool(std::function<void()>)>;

  HullOutputs(ros::NodeHandle nh, std::string world_frame, const HullStream* hull, Post post);
  /// Advertises the topics: once `post` can take tasks (a new subscriber's connect callback
  /// posts one at once).
  void advertise();

  /// Every output (the lazy ones only while subscribed, unless `all`) stamped `stamp`, from the
  /// hull as it is (the empty map when it has none), the cached tree, compact map and mesh made
  /// anew, and the snapshot. Throws what the conversions throw (a hull beyond OctoMap's keys).
  void publish(ros::Time stamp, bool all = false);
  /// From the next publication on, the occupied centres' clouds carry the colours of `mesh` (a
  /// mesh with one colour per vertex, as photo carving makes it; colourOctomap says how a voxel
  /// gets its colour) in PCL's `rgb` field, and with `colour_full_map` octomap_full is OctoMap's
  /// ColorOcTree. Null: colourless again.
  void setColours(std::shared_ptr<const TriangleMesh> mesh, bool colour_full_map);
  /// The centres' clouds carry `rgb` from the first publication on, white until setColours gives
  /// colours, so that a subscriber sees one point type throughout (rviz keeps the colour
  /// transformer the first cloud allowed).
  void colourClouds() { colour_clouds_ = true; }
  /// Keeps the full map (octomap_full) in every snapshot from the next publication on.
  void keepFullMap() { keep_full_ = true; }
  bool keepsFullMap() const { return keep_full_; }
  /// The last publication's maps; null before the first hull, after a reset, and for the full
  /// map until keepFullMap() and a publication.
  std::shared_ptr<const sift_hull::Octomap> binarySnapshot() const;
  std::shared_ptr<const sift_hull::Octomap> fullSnapshot() const;
  /// The last publication's carving box as `sift_hull hull --box` takes it (boxText); empty
  /// without a hull.
  std::string carvingBoxText() const;

  /// A hull was published since the start or the last publication without one.
  bool published() const { return published_; }
  const std_msgs::Header& header() const { return header_; }
  /// The published hull as an OctoMap (carved space free) and its mesh, made when first asked
  /// for after a publication. Require published().
  const octomap::OcTree& tree();
  const TriangleMesh& mesh();
  /// tree() coloured by the mesh setColours gave, made when first asked for after a publication.
  /// Requires published() and that mesh.
  const octomap::ColorOcTree& colourTree();
  /// ~save: the published hull's octree and mesh (savePaths(path)), each a regular file written
  /// through a temporary beside it. False, with why in `message`, before the first hull, for a
  /// path that holds a NUL or names something other than a regular file, or when writing fails.
  bool save(const std::string& path, std::string* message);

 private:
  struct Output {
    std::function<ros::Publisher()> advertise;
    ros::Publisher pub;
    bool lazy = true;
    bool holds_copy = false;  ///< its latched message is the current one
    bool centres = false;     ///< the occupied centres (the compact map is made with them then)
    std::function<void()> send;
  };
  template <typename Message>
  void add(const std::string& topic, bool lazy, std::function<Message()> hull,
           std::function<Message()> empty);
  void send(size_t output);
  const CompactOctomap& compact(bool centres);
  sensor_msgs::PointCloud2 centresCloud();
  sift_hull::Octomap fullMessage();
  visualization_msgs::Marker boxMarker();
  octomap::OcTree emptyTree() const { return octomap::OcTree(empty_resolution_m_); }

  ros::NodeHandle nh_;
  const std::string world_frame_;
  const HullStream* hull_;
  Post post_;
  std::vector<Output> outputs_;
  bool published_ = false;
  std_msgs::Header header_;
  double empty_resolution_m_ = 0.1;  ///< of the empty map: the last hull's
  std::unique_ptr<octomap::OcTree> tree_;
  std::unique_ptr<CompactOctomap> compact_;
  bool compact_centres_ = false;  ///< compact_ has the centres
  bool centres_wanted_ = false;   ///< a subscriber of this publication wants them
  std::unique_ptr<TriangleMesh> mesh_;
  std::shared_ptr<const TriangleMesh> colour_mesh_;  ///< setColours()
  bool colour_full_map_ = false;
  bool colour_clouds_ = false;
  std::unique_ptr<octomap::ColorOcTree> colour_tree_;
  std::atomic<bool> keep_full_{false};
  mutable std::mutex snapshot_mutex_;  ///< guards the three below
  std::shared_ptr<const sift_hull::Octomap> binary_snapshot_, full_snapshot_;
  std::string box_text_;  ///< carvingBoxText(), guarded as the snapshots
};

}  // namespace sift_hull
