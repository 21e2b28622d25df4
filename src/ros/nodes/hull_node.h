#pragma once

#include <image_transport/image_transport.h>
#include <image_transport/subscriber_filter.h>
#include <message_filters/subscriber.h>
#include <message_filters/time_synchronizer.h>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <std_srvs/Empty.h>
#include <tf2_ros/buffer.h>

#include <atomic>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <vector>

#include "lib/hull_counts.h"
#include "lib/hull_outputs.h"
#include "lib/node_diagnostics.h"
#include "lib/pairing_watch.h"
#include "lib/pose_wait.h"
#include "lib/tf_listener.h"
#include "lib/throttled_log.h"
#include "lib/work_queue.h"
#include "nodes/hull_node_config.h"
#include "sift_hull/BoundingBoxQuery.h"
#include "sift_hull/GetOctomap.h"
#include "sift_hull/Octomap.h"
#include "sift_hull/Save.h"
#include "sift_hull/SurfacePoints.h"
#include "sift_hull/hull/bounding_box.h"
#include "sift_hull/hull/view_silhouette_set.h"
#include "sift_hull/mvs/photo_stream.h"
#include "sift_hull/refine/point_carved_stream.h"

namespace sift_hull {

/// The hull node: silhouettes (mono8, through image_transport) with the camera_info beside them
/// (the silhouette topic's namespace + camera_info, image_transport's convention), once tf knows
/// the camera's pose in the world frame, refine a visual hull; surface points of calibrated pairs
/// (`surface_points`) carve it further. The results are published latched after every change.
/// Its OctoMap interface is octomap_server's: the topics octomap_binary, octomap_full,
/// octomap_point_cloud_centers, occupied_cells_vis_array and free_cells_vis_array, the services
/// octomap_binary and octomap_full (GetOctomap), ~clear_bbx (BoundingBoxQuery) and ~reset.
///
/// Threads: callbacks only take messages in. One worker thread owns the hull: it makes and carves
/// the views, takes the surface points, refines, clears boxes, resets, saves and publishes, one
/// step at a time. The services that need the hull run on the worker and wait for it at most
/// kServiceWait_s; octomap_binary answers from the last publication at once.
///
/// Data flow: silhouette + camera_info, paired by stamp -> PoseWait (tf2 filter, timeout) ->
/// the views' queue (bounded, the oldest dropped and counted) -> a checked view ->
/// PointCarvedStream::add -> the outputs table. surface_points -> a tf2 filter -> a bounded queue
/// -> PointCarvedStream::addSurfacePoints; a wall timer asks the worker to refine.
class HullNode {
 public:
  /// Reads the private parameters (ros_params.h) and subscribes.
  HullNode(ros::NodeHandle nh, ros::NodeHandle private_nh);
  /// With config structs, no parameter server needed.
  HullNode(ros::NodeHandle nh, ros::NodeHandle private_nh, HullNodeConfig node_config,
           HullStreamConfig hull_config);
  ~HullNode();

  /// Wall time a service waits for the worker (clearing, resetting, saving, a first octomap_full).
  static constexpr double kServiceWait_s = 1.0;
  /// Wall time ~save waits for the worker and the files.
  static constexpr double kSaveWait_s = 10.0;

 private:
  using Sync = message_filters::TimeSynchronizer<sensor_msgs::Image, sensor_msgs::CameraInfo>;
  /// ~photo_carve without from_image: the silhouette, its camera_info and the photograph.
  using PhotoSync = message_filters::TimeSynchronizer<sensor_msgs::Image, sensor_msgs::CameraInfo,
                                                      sensor_msgs::Image>;
  /// A posed silhouette waiting to be made a view and carved.
  struct Posed {
    sensor_msgs::ImageConstPtr silhouette;
    sensor_msgs::CameraInfoConstPtr info;
    Eigen::Isometry3d T_W_C;
    uint64_t generation = 0;           ///< of ~reset, so that views from before one are not carved
    sensor_msgs::ImageConstPtr photo;  ///< ~photo_carve without from_image: the photograph
  };
  /// A checked view.
  struct View {
    std::string name;
    PinholeCamera camera;
    cv::Mat mask;
    ros::Time stamp;
  };
  /// A pair's surface points with the pose of their frame.
  struct PosedPoints {
    sift_hull::SurfacePointsConstPtr message;
    Eigen::Isometry3d T_W_F;
  };
  // Input (callbacks).
  void subscribe();
  void onArrival(const sensor_msgs::ImageConstPtr& silhouette);
  void onInfoArrival(const sensor_msgs::CameraInfoConstPtr& info);
  /// A silhouette and its camera_info, paired by stamp: on to PoseWait.
  void onPair(const sensor_msgs::ImageConstPtr& silhouette,
              const sensor_msgs::CameraInfoConstPtr& info);
  void onPosed(const sensor_msgs::ImageConstPtr& silhouette,
               const sensor_msgs::CameraInfoConstPtr& info, const Eigen::Isometry3d& T_W_C);
  void onSurfacePoints(const sift_hull::SurfacePointsConstPtr& message);
  // Photo carving (hull_node_photo.cpp).
  void subscribePhotos(const std::string& silhouette_topic);
  /// A silhouette, its camera_info and its photograph, paired by stamp: on to PoseWait, the
  /// photograph kept aside until the silhouette has its pose.
  void onPhotoTriple(const sensor_msgs::ImageConstPtr& silhouette,
                     const sensor_msgs::CameraInfoConstPtr& info,
                     const sensor_msgs::ImageConstPtr& photo);
  /// The photograph kept aside for `silhouette` (null: none), no longer kept.
  sensor_msgs::ImageConstPtr takePhoto(const sensor_msgs::ImageConstPtr& silhouette);
  /// The worker: a carved view's photograph to the photo stream.
  void keepPhoto(const Posed& posed, const View& view);
  /// The worker: a finished pass carved into the hull and its colours published; the next pass.
  void takePhotoPass();
  void startPhotoPass();
  void reportPhotoDiagnostics(diagnostic_updater::DiagnosticStatusWrapper& status);
  // Work (the worker thread).
  // Views segmented together (hull_node_views.cpp).
  /// The view the three messages make, or false with the reason logged.
  bool viewOf(const Posed& posed, View* view);
  /// ~from_image with the views or auto method: together_ made.
  void startSegmentingTogether();
  /// Every kept view's silhouette made anew from all of them and the hull carved again from
  /// them (the surface points kept); whether the hull changed. A failure is logged.
  bool segmentTogether();
  void reportSegmentation(diagnostic_updater::DiagnosticStatusWrapper& status);
  void integrate(Posed& posed);
  /// Whether the view changed the hull; what the stream made of it in `outcome`.
  bool carve(const View& view, HullStream::Outcome* outcome);
  void takeSurfacePoints();
  void mergeSurfacePoints(const PosedPoints& posed);
  void refineIfDue();
  void continueRefining();
  /// Logs a problem (throttled) and keeps it for /diagnostics.
  void problem(const std::string& prefix, const std::string& why);
  /// outputs_.publish(unpublished_stamp_) when views were carved since the last publication.
  void publishPending();
  /// outputs_.publish, its failure logged.
  void publish(ros::Time stamp, bool all = false);  // by value: callers pass members it resets
  // Services and diagnostics.
  void advertiseServices();
  bool reset(std_srvs::Empty::Request& request, std_srvs::Empty::Response& response);
  void resetOnWorker();
  bool save(sift_hull::Save::Request& request, sift_hull::Save::Response& response);
  sift_hull::Save::Response saveOnWorker(const std::string& path);
  bool getMap(bool binary, sift_hull::GetOctomap::Response* response);
  bool clearBbx(sift_hull::BoundingBoxQuery::Request& request,
                sift_hull::BoundingBoxQuery::Response& response);
  void reportDiagnostics(diagnostic_updater::DiagnosticStatusWrapper& status);

  // Destroyed bottom up: subscriptions and services first, then the worker, then what it uses.
  ros::NodeHandle nh_, private_nh_;
  HullNodeConfig config_;
  /// ~skip_views: frame ids (HullStream skips them) and FRAME@SEC.NSEC, one view of a moving
  /// camera.
  const std::set<std::string> skip_views_;
  // The worker's own.
  PointCarvedStream hull_;
  ros::Time unpublished_stamp_;      ///< newest view that changed the hull since then (zero: none)
  ros::WallTime last_publish_wall_;  ///< of the last publication
  ros::WallTime last_trim_wall_;     ///< of the last return of freed memory to the system
  // Shared with the callbacks and services.
  std::atomic<uint64_t> generation_{0};
  std::atomic<bool> refine_posted_{false}, points_posted_{false};
  std::mutex problem_mutex_;  ///< guards last_problem_
  std::string last_problem_;
  BoundedQueue<PosedPoints> points_;  ///< pairs waiting for the worker
  ThrottledLog log_;
  HullCounts counts_;
  std::atomic<double> last_carve_ms_{0.0}, last_publish_ms_{0.0}, last_view_stamp_{0.0};
  // The last refinement by surface points: from its first slice to its end, and its longest slice.
  std::atomic<double> last_refine_ms_{0.0}, longest_refine_slice_ms_{0.0};
  ros::WallTime refine_start_;     ///< of the refinement in progress (worker)
  double refine_slices_ms_ = 0.0;  ///< its longest slice so far (worker)
  ros::WallTime start_wall_;
  WorkQueue<Posed> work_;
  HullOutputs outputs_;   ///< after the worker it posts new subscribers to
  PairingWatch pairing_;  ///< silhouettes and camera_infos that arrive but do not pair
  ros::WallTimer refine_timer_;
  tf2_ros::Buffer tf_buffer_;
  TfListener tf_listener_;
  PoseWait pose_wait_;
  // ~from_image with the views or auto method (null otherwise): the photographs kept at the
  // working size (worker).
  std::unique_ptr<ViewSilhouetteSet> together_;
  ros::Time newest_view_stamp_;  ///< of the views carved (worker)
  std::atomic<uint64_t> segmentations_{0}, segmentations_failed_{0};
  std::atomic<double> last_segmentation_ms_{0.0}, last_agreement_{0.0};
  std::mutex segmentation_mutex_;  ///< guards last_segmentation_method_
  std::string last_segmentation_method_;
  // Photo carving (null without ~photo_carve): the passes post their end to the worker.
  std::unique_ptr<PhotoStream> photo_;
  std::mutex photos_mutex_;  ///< guards photos_
  /// Photographs whose silhouettes wait for their pose, oldest first, at most 2 ~queue_size.
  std::deque<std::pair<sensor_msgs::ImageConstPtr, sensor_msgs::ImageConstPtr>> photos_;
  std::atomic<uint64_t> photo_passes_applied_{0}, photo_passes_stale_{0}, photo_passes_failed_{0};
  std::atomic<uint64_t> photo_views_{0}, photo_views_left_out_{0}, photo_carved_voxels_{0};
  std::atomic<uint64_t> photo_unpaired_{0}, last_photo_pass_views_{0};
  std::atomic<bool> photo_pass_running_{false};
  std::atomic<double> last_photo_pass_ms_{0.0}, last_photo_apply_ms_{0.0};
  NodeDiagnostics diagnostics_;  ///< after what it reports on (the pose wait's count)
  // Subscribed last, once every callback is in place.
  image_transport::ImageTransport image_transport_;
  image_transport::SubscriberFilter silhouette_sub_;
  message_filters::Subscriber<sensor_msgs::CameraInfo> info_sub_;
  Sync sync_;
  image_transport::SubscriberFilter photo_sub_;
  PhotoSync photo_sync_;
  message_filters::Subscriber<sift_hull::SurfacePoints> points_sub_;
  ros::ServiceServer reset_srv_, save_srv_, binary_srv_, full_srv_, clear_bbx_srv_;
};

}  // namespace sift_hull
