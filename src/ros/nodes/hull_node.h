#pragma once

#include <message_filters/subscriber.h>
#include <message_filters/time_synchronizer.h>
#include <octomap/OcTree.h>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud2.h>
#include <std_srvs/Empty.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/message_filter.h>
#include <tf2_ros/transform_listener.h>

#include <atomic>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "lib/node_diagnostics.h"
#include "nodes/hull_node_config.h"
#include "lib/pairing_watch.h"
#include "lib/pose_gate.h"
#include "lib/pose_waits.h"
#include "lib/throttled_log.h"
#include "lib/work_queue.h"
#include "sift_hull/BoundingBoxQuery.h"
#include "sift_hull/GetOctomap.h"
#include "sift_hull/Save.h"
#include "sift_hull/SurfacePoints.h"
#include "sift_hull/hull/bounding_box.h"
#include "sift_hull/hull/hull_stream.h"
#include "sift_hull/hull/mesh.h"
#include "sift_hull/hull/silhouette.h"
#include "sift_hull/io/calibration.h"
#include "sift_hull/refine/free_space.h"
#include "sift_hull/refine/surface_points.h"

namespace sift_hull {


/// The hull node: silhouettes (mono8) with the camera_info beside them (the silhouette topic's
/// namespace + camera_info, image_transport's convention), once tf knows the camera's pose in
/// the world frame, refine a visual hull; the results are published latched after every view.
/// Its OctoMap interface is octomap_server's: the topics octomap_binary, octomap_full,
/// octomap_point_cloud_centers, occupied_cells_vis_array and free_cells_vis_array, the services
/// octomap_binary and octomap_full (GetOctomap), ~clear_bbx (BoundingBoxQuery) and ~reset.
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

  void onView(const sensor_msgs::ImageConstPtr& silhouette,
              const sensor_msgs::CameraInfoConstPtr& info);
  /// The view's mask: the silhouette message, or the one extracted from the image.
  cv::Mat maskOf(const sensor_msgs::ImageConstPtr& message, std::string* why_not) const;
  bool cameraOf(const sensor_msgs::Image& silhouette, const sensor_msgs::CameraInfo& info,
                PinholeCamera* camera);
  void integrate(View& view);
  /// Whether the view changed the hull.
  bool carve(const View& view);
  /// The hull, stamped `stamp`: octomap_binary and the centres always, the other outputs while
  /// someone subscribes; OctoMap's tree is built for those, or when first asked for.
  void publish(const ros::Time& stamp);
  /// The published hull as an OctoMap (carved space free, the cleared boxes applied), built from
  /// the stream when stale. Requires published_ and hull_mutex_.
  const octomap::OcTree& publishedTree();
  /// The maps, stamped header_: octomap_binary and the centres from compactOctomap (or the tree,
  /// once boxes were cleared), the full map and the markers from publishedTree when subscribed.
  void publishMaps();
  /// The occupied cells' centres on occupied_cells and octomap_point_cloud_centers.
  void publishCentres(const sensor_msgs::PointCloud2& centres);
  /// publish(unpublished_stamp_) when views were carved since the last publication.
  void publishPending();
  /// `send` under the hull's lock after publishPending, when a hull is published; what throws is
  /// logged (never into roscpp's callback).
  void sendToNewSubscriber(const std::function<void()>& send);
  /// octomap_full, markers and mesh for a new subscriber (they are built only while someone
  /// looks).
  void publishFullNow();
  void publishMarkersNow();
  void publishFreeMarkersNow();
  void publishMeshNow();
  /// The current centres cloud on `pub` (occupied_cells or octomap_point_cloud_centers).
  void publishCentresNow(ros::Publisher* pub);
  void publishEmpty(double resolution_m);
  /// The published hull's mesh (marching cubes once per hull, shared by `mesh`, new subscribers
  /// and ~save). Requires published_.
  const TriangleMesh& publishedMesh();
  void reportDiagnostics(diagnostic_updater::DiagnosticStatusWrapper& status);
  void onPoseMissing(const sensor_msgs::ImageConstPtr& silhouette,
                     tf2_ros::filter_failure_reasons::FilterFailureReason reason);
  void onArrival(const sensor_msgs::ImageConstPtr& silhouette);
  void onInfoArrival(const sensor_msgs::CameraInfoConstPtr& info);
  void onPoseTooLate(const sensor_msgs::ImageConstPtr& silhouette);
  void reportPoseTimeouts();
  void subscribe();
  bool reset(std_srvs::Empty::Request& request, std_srvs::Empty::Response& response);
  bool save(sift_hull::Save::Request& request, sift_hull::Save::Response& response);
  /// octomap_binary / octomap_full: the map as last published; false before the first hull.
  bool getMap(bool binary, sift_hull::GetOctomap::Response* response);
  /// ~clear_bbx: the box's known voxels free, now and in every later map until ~reset.
  bool clearBbx(sift_hull::BoundingBoxQuery::Request& request,
                sift_hull::BoundingBoxQuery::Response& response);
  void advertiseServices();
  /// Free-space carving (hull_node_refine.cpp): a pair's surface points, taken into the world
  /// frame by tf and kept (at most max_surface_points); the hull is refined with every point kept
  /// at most every refine_period_s, and again after the tree starts anew (a refit of the box).
  void onSurfacePoints(const sift_hull::SurfacePointsConstPtr& message);
  void refineIfDue();
  /// Requires hull_mutex_ and a hull.
  void refineWithPoints();
  struct PairPoints {
    PinholeCamera left, right;
    std::vector<SurfacePoint> points;  ///< views 0 (left) and 1 (right)
    ros::Time stamp;
  };

  // Destroyed bottom up: subscriptions and services first, then the worker, then what it uses.
  ros::NodeHandle nh_, private_nh_;
  HullNodeConfig config_;
  /// Guards stream_, octree_, mesh_, header_, cleared_boxes_ and generation_ (the worker, ~reset,
  /// ~save, new subscribers).
  std::mutex hull_mutex_;
  HullStream stream_;
  std::unique_ptr<octomap::OcTree> octree_;  ///< the hull as last published (publishedTree)
  bool published_ = false;                   ///< a hull was published since the start or ~reset
  bool tree_stale_ = false;                  ///< octree_ is older than the published hull
  std::unique_ptr<TriangleMesh> mesh_;       ///< its mesh, made when first asked for
  std_msgs::Header header_;                  ///< of the last publication
  ros::Time unpublished_stamp_;       ///< newest view that changed the hull since then (zero: none)
  ros::WallTime last_publish_wall_;   ///< of the last publication
  std::vector<Box3d> cleared_boxes_;  ///< by ~clear_bbx since the start or ~reset
  std::atomic<uint64_t> generation_{0};
  ThrottledLog log_;
  ros::Publisher octomap_pub_, octomap_full_pub_, cloud_pub_, centers_pub_, markers_pub_,
      free_markers_pub_, mesh_pub_;
  std::atomic<double> last_carve_ms_{0.0}, last_publish_ms_{0.0}, last_view_stamp_{0.0};
  std::atomic<size_t> redundant_views_{0};
  std::atomic<size_t> refused_views_{0};
  /// Views dropped because their pose did not come within ~pose_timeout_s, or never.
  std::atomic<size_t> views_without_pose_{0};
  WorkQueue<View> work_;
  PairingWatch pairing_;  ///< silhouettes and camera_infos that arrive but do not pair
  NodeDiagnostics diagnostics_;
  PoseWaits pose_waits_;
  ros::WallTimer pose_timer_, refine_timer_;
  std::mutex points_mutex_;       ///< guards pairs_, stored_points_ and refine_pending_
  std::deque<PairPoints> pairs_;  ///< the surface points kept, oldest first
  size_t stored_points_ = 0;
  bool refine_pending_ = false;
  uint64_t refined_generation_ = 0;  ///< the stream's hull generation last carved with points
  std::atomic<size_t> free_voxels_{0};
  tf2_ros::Buffer tf_buffer_;
  tf2_ros::TransformListener tf_listener_;
  // Subscribed last, once every callback is in place.
  message_filters::Subscriber<sensor_msgs::Image> silhouette_sub_;
  message_filters::Subscriber<sensor_msgs::CameraInfo> info_sub_;
  tf2_ros::MessageFilter<sensor_msgs::Image> pose_filter_;
  PoseGate pose_gate_;
  Sync sync_;
  ros::Subscriber surface_points_sub_;
  ros::ServiceServer reset_srv_, save_srv_, binary_srv_, full_srv_, clear_bbx_srv_;
};

}  // namespace sift_hull
