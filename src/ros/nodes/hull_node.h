#pragma once

#include <message_filters/subscriber.h>
#include <message_filters/time_synchronizer.h>
#include <octomap/OcTree.h>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <std_srvs/Empty.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include <atomic>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "lib/node_diagnostics.h"
#include "lib/pairing_watch.h"
#include "lib/pose_wait.h"
#include "lib/throttled_log.h"
#include "lib/work_queue.h"
#include "nodes/hull_node_config.h"
#include "sift_hull/BoundingBoxQuery.h"
#include "sift_hull/GetOctomap.h"
#include "sift_hull/Save.h"
#include "sift_hull/SurfacePoints.h"
#include "sift_hull/hull/bounding_box.h"
#include "sift_hull/hull/hull_octomap.h"
#include "sift_hull/hull/mesh.h"
#include "sift_hull/refine/point_carved_stream.h"

namespace sift_hull {

/// The hull node: silhouettes (mono8) with the camera_info beside them (the silhouette topic's
/// namespace + camera_info, image_transport's convention), once tf knows the camera's pose in
/// the world frame, refine a visual hull; surface points of calibrated pairs (`surface_points`)
/// carve it further. The results are published latched after every change.
/// Its OctoMap interface is octomap_server's: the topics octomap_binary, octomap_full,
/// octomap_point_cloud_centers, occupied_cells_vis_array and free_cells_vis_array, the services
/// octomap_binary and octomap_full (GetOctomap), ~clear_bbx (BoundingBoxQuery) and ~reset.
///
/// Data flow: silhouette + camera_info, paired by stamp -> PoseWait (tf2 filter, timeout) ->
/// a checked View -> the work queue -> PointCarvedStream::add on the worker thread -> the outputs
/// table. surface_points -> PointCarvedStream::addSurfacePoints; a wall timer refines.
class HullNode {
 public:
  /// Reads the private parameters (ros_params.h) and subscribes.
  HullNode(ros::NodeHandle nh, ros::NodeHandle private_nh);
  /// With config structs, no parameter server needed.
  HullNode(ros::NodeHandle nh, ros::NodeHandle private_nh, HullNodeConfig node_config,
           HullStreamConfig hull_config);

 private:
  using Sync = message_filters::TimeSynchronizer<sensor_msgs::Image, sensor_msgs::CameraInfo>;
  /// A checked view waiting to be carved.
  struct View {
    std::string name;
    PinholeCamera camera;
    cv::Mat mask;
    ros::Time stamp;
    uint64_t generation = 0;  ///< of ~reset, so that views from before one are not carved
  };
  /// A published output: built after every change (lazy: only while someone subscribes) and for
  /// each new subscriber; `send` publishes the current hull, or the empty map after ~reset.
  struct Output {
    ros::Publisher pub;
    bool lazy = true;
    bool map = true;       ///< republished after ~clear_bbx (the mesh is not: boxes do not cut it)
    bool centres = false;  ///< the occupied centres (the compact map is made with them then)
    std::function<void()> send;
  };

  // Input.
  void subscribe();
  /// Counted by PairingWatch, for /diagnostics.
  void onArrival(const sensor_msgs::ImageConstPtr& silhouette);
  void onInfoArrival(const sensor_msgs::CameraInfoConstPtr& info);
  /// A silhouette and its camera_info, paired by stamp: on to PoseWait.
  void onPair(const sensor_msgs::ImageConstPtr& silhouette,
              const sensor_msgs::CameraInfoConstPtr& info);
  void onPosed(const sensor_msgs::ImageConstPtr& silhouette,
               const sensor_msgs::CameraInfoConstPtr& info, const Eigen::Isometry3d& T_W_C);
  /// The view the three messages make, or false with the reason logged.
  bool viewOf(const sensor_msgs::ImageConstPtr& silhouette, const sensor_msgs::CameraInfo& info,
              const Eigen::Isometry3d& T_W_C, View* view);
  void onSurfacePoints(const sift_hull::SurfacePointsConstPtr& message);
  // Work (the worker thread and the refinement timer).
  void integrate(View& view);
  /// Whether the view changed the hull.
  bool carve(const View& view);
  void refineIfDue();
  // Output.
  template <typename Message>
  void addOutput(const std::string& topic, bool lazy, std::function<Message()> hull,
                 std::function<Message()> empty);
  void advertiseOutputs();
  /// The outputs, stamped `stamp`: the maps, and the rest when the hull changed (its cached tree,
  /// compact map and mesh made anew); the lazy ones only while subscribed, unless `all`.
  void publish(const ros::Time& stamp, bool hull_changed = true, bool all = false);
  /// publish(unpublished_stamp_) when views were carved since the last publication.
  void publishPending();
  void sendToNewSubscriber(size_t output);
  /// The published hull as an OctoMap (carved space free, the cleared boxes applied), its compact
  /// map (centres when asked) and its mesh, each made when first asked for after a change.
  /// Require published_ and hull_mutex_.
  const octomap::OcTree& publishedTree();
  const CompactOctomap& publishedCompact(bool centres);
  const TriangleMesh& publishedMesh();
  // Services and diagnostics.
  void advertiseServices();
  bool reset(std_srvs::Empty::Request& request, std_srvs::Empty::Response& response);
  bool save(sift_hull::Save::Request& request, sift_hull::Save::Response& response);
  /// octomap_binary / octomap_full: the map as last published; false before the first hull.
  bool getMap(bool binary, sift_hull::GetOctomap::Response* response);
  /// ~clear_bbx: the box's known voxels free, now and in every later map until ~reset.
  bool clearBbx(sift_hull::BoundingBoxQuery::Request& request,
                sift_hull::BoundingBoxQuery::Response& response);
  void reportDiagnostics(diagnostic_updater::DiagnosticStatusWrapper& status);

  // Destroyed bottom up: subscriptions and services first, then the worker, then what it uses.
  ros::NodeHandle nh_, private_nh_;
  HullNodeConfig config_;
  /// Guards hull_ and the published state below (the worker, the timer, services, subscribers).
  std::mutex hull_mutex_;
  PointCarvedStream hull_;
  bool published_ = false;                   ///< a hull was published since the start or ~reset
  std::unique_ptr<octomap::OcTree> tree_;    ///< publishedTree()
  std::unique_ptr<CompactOctomap> compact_;  ///< publishedCompact()
  bool compact_centres_ = false;             ///< compact_ has the centres
  bool centres_wanted_ = false;              ///< a subscriber of this publication wants them
  std::unique_ptr<TriangleMesh> mesh_;       ///< publishedMesh()
  double empty_resolution_m_ = 0.1;          ///< of the empty map published after ~reset
  std_msgs::Header header_;                  ///< of the last publication
  ros::Time unpublished_stamp_;       ///< newest view that changed the hull since then (zero: none)
  ros::WallTime last_publish_wall_;   ///< of the last publication
  std::vector<Box3d> cleared_boxes_;  ///< by ~clear_bbx since the start or ~reset
  std::atomic<uint64_t> generation_{0};
  ThrottledLog log_;
  std::vector<Output> outputs_;
  std::atomic<double> last_carve_ms_{0.0}, last_publish_ms_{0.0}, last_view_stamp_{0.0};
  std::atomic<size_t> redundant_views_{0}, refused_views_{0}, free_voxels_{0};
  WorkQueue<View> work_;
  PairingWatch pairing_;  ///< silhouettes and camera_infos that arrive but do not pair
  ros::WallTimer refine_timer_;
  tf2_ros::Buffer tf_buffer_;
  tf2_ros::TransformListener tf_listener_;
  PoseWait pose_wait_;
  NodeDiagnostics diagnostics_;  ///< after what it reports on (the pose wait's count)
  // Subscribed last, once every callback is in place.
  message_filters::Subscriber<sensor_msgs::Image> silhouette_sub_;
  message_filters::Subscriber<sensor_msgs::CameraInfo> info_sub_;
  Sync sync_;
  ros::Subscriber surface_points_sub_;
  ros::ServiceServer reset_srv_, save_srv_, binary_srv_, full_srv_, clear_bbx_srv_;
};

}  // namespace sift_hull
