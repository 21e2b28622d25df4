#include "nodes/hull_node.h"

#include <image_transport/camera_common.h>
#include <tf2_eigen/tf2_eigen.h>

#include <sstream>

#include "lib/conversions.h"
#include "lib/node_diagnostics.h"
#include "lib/ros_params.h"
#include "lib/save_paths.h"
#include "sift_hull/hull/hull_octomap.h"
#include "sift_hull/hull/mesh.h"
#include "sift_hull/hull/silhouette.h"
#include "sift_hull/io/ply.h"

namespace sift_hull {
namespace {

constexpr double kThrottle_s = 5.0;
/// Wall time inputs may arrive without pairing before /diagnostics warns.
constexpr double kPairingPatience_s = 5.0;
/// Wall time a changed hull may wait for the queue to drain before it is published anyway.
constexpr double kMaxPublishDelay_s = 1.0;

std::string shortNumber(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

}  // namespace

HullNode::HullNode(ros::NodeHandle nh, ros::NodeHandle private_nh)
    : HullNode(nh, private_nh, ros_params::readHullNodeConfig(private_nh),
               ros_params::readHullStreamConfig(private_nh)) {}

HullNode::HullNode(ros::NodeHandle nh, ros::NodeHandle private_nh, HullNodeConfig node_config,
                   HullStreamConfig hull_config)
    : nh_(nh),
      private_nh_(private_nh),
      config_(std::move(node_config)),
      stream_(std::move(hull_config)),
      octomap_pub_(nh_.advertise<sift_hull::Octomap>("octomap_binary", 1, true)),
      octomap_full_pub_(nh_.advertise<sift_hull::Octomap>(
          "octomap_full", 1, [this](const ros::SingleSubscriberPublisher&) { publishFullNow(); },
          ros::SubscriberStatusCallback(), ros::VoidConstPtr(), true)),
      cloud_pub_(nh_.advertise<sensor_msgs::PointCloud2>(
          "occupied_cells", 1,
          [this](const ros::SingleSubscriberPublisher&) { publishCentresNow(&cloud_pub_); },
          ros::SubscriberStatusCallback(), ros::VoidConstPtr(), true)),
      centers_pub_(nh_.advertise<sensor_msgs::PointCloud2>(
          "octomap_point_cloud_centers", 1,
          [this](const ros::SingleSubscriberPublisher&) { publishCentresNow(&centers_pub_); },
          ros::SubscriberStatusCallback(), ros::VoidConstPtr(), true)),
      markers_pub_(nh_.advertise<visualization_msgs::MarkerArray>(
          "occupied_cells_vis_array", 1,
          [this](const ros::SingleSubscriberPublisher&) { publishMarkersNow(); },
          ros::SubscriberStatusCallback(), ros::VoidConstPtr(), true)),
      free_markers_pub_(nh_.advertise<visualization_msgs::MarkerArray>(
          "free_cells_vis_array", 1,
          [this](const ros::SingleSubscriberPublisher&) { publishFreeMarkersNow(); },
          ros::SubscriberStatusCallback(), ros::VoidConstPtr(), true)),
      mesh_pub_(nh_.advertise<visualization_msgs::Marker>(
          "mesh", 1, [this](const ros::SingleSubscriberPublisher&) { publishMeshNow(); },
          ros::SubscriberStatusCallback(), ros::VoidConstPtr(), true)),
      work_(config_.queue_size, 1, [this](View& view) { integrate(view); }),
      pairing_({config_.from_image ? "image" : "silhouette", "camera_info"}, kPairingPatience_s,
               "a silhouette pairs with the camera_info of an equal stamp once tf has its "
               "camera's pose in ~world_frame (a node making masks must copy its image's header: "
               "stamp and frame_id)"),
      diagnostics_(nh_, private_nh_, "hull", config_.diagnostic_period,
                   [this](diagnostic_updater::DiagnosticStatusWrapper& status) {
                     reportDiagnostics(status);
                   }),
      pose_waits_(config_.pose_timeout_s, 4 * static_cast<size_t>(config_.queue_size)),
      tf_listener_(tf_buffer_),
      pose_filter_(tf_buffer_, config_.world_frame, config_.queue_size, nh_),
      pose_gate_(&pose_waits_,
                 [this](const sensor_msgs::ImageConstPtr& late) { onPoseTooLate(late); }),
      sync_(config_.queue_size) {
  pose_timer_ = nh_.createWallTimer(ros::WallDuration(0.2),
                                    [this](const ros::WallTimerEvent&) { reportPoseTimeouts(); });
  refine_timer_ = nh_.createWallTimer(ros::WallDuration(config_.refine_period_s),
                                      [this](const ros::WallTimerEvent&) { refineIfDue(); });
  advertiseServices();
  subscribe();
}

void HullNode::subscribe() {
  pose_filter_.setTolerance(ros::Duration(0.0));
  pose_filter_.registerFailureCallback(
      [this](const sensor_msgs::ImageConstPtr& image,
             tf2_ros::filter_failure_reasons::FilterFailureReason reason) {
        onPoseMissing(image, reason);
      });
  silhouette_sub_.registerCallback(&HullNode::onArrival, this);
  info_sub_.registerCallback(&HullNode::onInfoArrival, this);
  pose_filter_.connectInput(silhouette_sub_);
  pose_gate_.connectInput(pose_filter_);
  sync_.connectInput(pose_gate_, info_sub_);
  sync_.registerCallback(&HullNode::onView, this);
  surface_points_sub_ = nh_.subscribe("surface_points", static_cast<uint32_t>(config_.queue_size),
                                      &HullNode::onSurfacePoints, this);
  // camera_info beside the image, wherever remapping put it (image_transport's convention).
  const std::string image_topic = nh_.resolveName(config_.from_image ? "image" : "silhouette");
  info_sub_.subscribe(nh_, image_transport::getCameraInfoTopic(image_topic), config_.queue_size);
  silhouette_sub_.subscribe(nh_, image_topic, config_.queue_size);
}

void HullNode::onInfoArrival(const sensor_msgs::CameraInfoConstPtr& info) {
  pairing_.arrived(1, info->header.stamp.toSec(), PairingWatch::Clock::now());
}

void HullNode::onArrival(const sensor_msgs::ImageConstPtr& silhouette) {
  pairing_.arrived(0, silhouette->header.stamp.toSec(), PairingWatch::Clock::now());
  pose_waits_.arrived(silhouette->header.frame_id, silhouette->header.stamp.toSec(),
                      PoseWaits::Clock::now());
}

void HullNode::reportPoseTimeouts() {
  for (const std::string& frame : pose_waits_.expire(PoseWaits::Clock::now())) {
    ++views_without_pose_;
    log_.error("hull: dropped a silhouette: ",
               "no pose of '" + frame + "' in '" + config_.world_frame + "' within " +
                   shortNumber(config_.pose_timeout_s) + " s (~pose_timeout_s)");
  }
}

void HullNode::onPoseTooLate(const sensor_msgs::ImageConstPtr& silhouette) {
  log_.error("hull: view '" + silhouette->header.frame_id + "' ignored: ",
             "its pose came after ~pose_timeout_s");
}

void HullNode::onPoseMissing(const sensor_msgs::ImageConstPtr& silhouette,
                             tf2_ros::filter_failure_reasons::FilterFailureReason reason) {
  if (pose_waits_.forget(silhouette->header.frame_id, silhouette->header.stamp.toSec()))
    ++views_without_pose_;
  const char* why = reason == tf2_ros::filter_failure_reasons::EmptyFrameID ? "empty frame id"
                    : reason == tf2_ros::filter_failure_reasons::OutTheBack
                        ? "older than the transforms tf keeps"
                        : "the transform never arrived";
  log_.error("hull: dropped a silhouette: ", "no pose of '" + silhouette->header.frame_id +
                                                 "' in '" + config_.world_frame + "' (" + why +
                                                 ")");
}

bool HullNode::cameraOf(const sensor_msgs::Image& silhouette, const sensor_msgs::CameraInfo& info,
                        PinholeCamera* camera) {
  Eigen::Isometry3d T_W_C;
  try {
    T_W_C = tf2::transformToEigen(tf_buffer_.lookupTransform(
        config_.world_frame, silhouette.header.frame_id, silhouette.header.stamp));
  } catch (const tf2::TransformException& e) {
    log_.error("hull: view ignored: ", e.what());
    return false;
  }
  std::string why_not;
  if (!ros_conversions::cameraFromInfo(info, T_W_C, cv::Size(silhouette.width, silhouette.height),
                                       camera, &why_not, config_.rectified)) {
    log_.error("hull: view '" + silhouette.header.frame_id + "' ignored: ", why_not);
    return false;
  }
  return true;
}

void HullNode::onView(const sensor_msgs::ImageConstPtr& silhouette,
                      const sensor_msgs::CameraInfoConstPtr& info) {
  pairing_.paired();
  std::string why_not;
  const cv::Mat mask = maskOf(silhouette, &why_not);
  if (mask.empty()) {
    log_.error("hull: view '" + silhouette->header.frame_id + "' ignored: ", why_not);
    return;
  }
  View view{silhouette->header.frame_id, {}, mask, silhouette->header.stamp, generation_};
  if (!cameraOf(*silhouette, *info, &view.camera)) return;
  pushCounted(&work_, std::move(view), "hull: views waiting to be carved (~queue_size)");
}

void HullNode::integrate(View& view) {
  std::lock_guard<std::mutex> lock(hull_mutex_);
  if (view.generation != generation_) return;  // queued before a ~reset
  const ros::WallTime start = ros::WallTime::now();
  const bool changed = carve(view);
  const ros::WallTime carved = ros::WallTime::now();
  last_carve_ms_ = (carved - start).toSec() * 1e3;
  redundant_views_ = stream_.redundantViews();
  last_view_stamp_ = view.stamp.toSec();
  if (changed) unpublished_stamp_ = view.stamp;
  if (stream_.hasHull() && stream_.hullGeneration() != refined_generation_) {
    std::lock_guard<std::mutex> points_lock(points_mutex_);
    refine_pending_ = refine_pending_ || !pairs_.empty();  // the points carve the new tree too
  }
  // Waiting, skipped or redundant: the published hull stands. Views queued behind this one refine
  // the hull at once: each state would cost a conversion the next view replaces, so the hull is
  // published when the queue has drained, or kMaxPublishDelay_s after the last publication under
  // a stream that never lets it drain, stamped with the newest view that changed it.
  if (unpublished_stamp_.isZero()) return;
  if (work_.counts().waiting > 0 &&
      (ros::WallTime::now() - last_publish_wall_).toSec() < kMaxPublishDelay_s) {
    return;
  }
  try {
    publish(unpublished_stamp_);
  } catch (const std::exception& e) {  // e.g. a hull beyond OctoMap's key range
    unpublished_stamp_ = ros::Time();
    log_.error("hull: cannot publish the hull: ", e.what());
  }
  last_publish_ms_ = (ros::WallTime::now() - carved).toSec() * 1e3;
}

void HullNode::reportDiagnostics(diagnostic_updater::DiagnosticStatusWrapper& status) {
  reportQueue(work_.counts(), "views", &status);
  status.add("views redundant", redundant_views_.load());
  status.add("views refused", refused_views_.load());
  status.add("views without pose", views_without_pose_.load());
  status.add("free voxels (surface_points)", free_voxels_.load());
  status.add("last view carve ms", last_carve_ms_.load());
  status.add("last view publish ms", last_publish_ms_.load());
  status.add("last view stamp", last_view_stamp_.load());
  const std::string unpaired = pairing_.problem(PairingWatch::Clock::now());
  if (!unpaired.empty()) {
    status.mergeSummary(diagnostic_msgs::DiagnosticStatus::WARN, unpaired);
    ROS_WARN_THROTTLE(kThrottle_s, "hull: %s", unpaired.c_str());
  }
}

cv::Mat HullNode::maskOf(const sensor_msgs::ImageConstPtr& message, std::string* why_not) const {
  if (!config_.from_image) return ros_conversions::maskFromImage(*message, why_not);
  const cv::Mat image = ros_conversions::eightBitImage(message, why_not);
  return image.empty() ? image : silhouetteFromImage(image, config_.recipe);
}

bool HullNode::carve(const View& view) {
  const std::string& name = view.name;
  try {
    const HullStream::Outcome outcome = stream_.add(name, view.camera, view.mask);
    for (const std::string& refusal : stream_.takeRefusals()) {
      log_.error("hull: view refused: ", refusal);
    }
    refused_views_ = stream_.refusedViews();
    if (outcome == HullStream::Outcome::kWaiting) {
      ROS_INFO_THROTTLE(kThrottle_s, "hull: %zu view(s) waiting for a bounding box: %s",
                        stream_.waitingViews(), stream_.whyNoBox().c_str());
    }
    if (outcome == HullStream::Outcome::kSkipped) ROS_INFO("hull: view '%s' skipped", name.c_str());
    if (outcome == HullStream::Outcome::kRedundant) {
      ROS_INFO_THROTTLE(kThrottle_s,
                        "hull: %zu view(s) left out so far: seen from where a view already taken "
                        "was (~min_view_distance_m, ~min_view_angle_deg)",
                        stream_.redundantViews());
    }
    return outcome == HullStream::Outcome::kCarved;
  } catch (const std::exception& e) {
    log_.error("hull: view '" + name + "' ignored: ", e.what());
    return false;
  }
}

bool HullNode::reset(std_srvs::Empty::Request&, std_srvs::Empty::Response&) {
  std::lock_guard<std::mutex> lock(hull_mutex_);
  ++generation_;
  const size_t discarded = work_.clear();  // views from before the reset
  const double resolution_m = stream_.hasHull() ? stream_.hull().cube().resolution_m
                              : octree_         ? octree_->getResolution()
                                                : 0.1;
  stream_.reset();
  {
    std::lock_guard<std::mutex> points_lock(points_mutex_);
    pairs_.clear();
    stored_points_ = 0;
    refine_pending_ = false;
  }
  free_voxels_ = 0;
  unpublished_stamp_ = ros::Time();
  cleared_boxes_.clear();
  refused_views_ = 0;
  publishEmpty(resolution_m);
  octree_.reset();
  published_ = false;
  mesh_.reset();
  ROS_INFO("hull: reset (%zu view(s) waiting to be carved discarded)", discarded);
  return true;
}

bool HullNode::save(sift_hull::Save::Request& request, sift_hull::Save::Response& response) {
  std::lock_guard<std::mutex> lock(hull_mutex_);
  try {
    publishPending();  // views carved but not yet published: saved as published
  } catch (const std::exception& e) {
    log_.error("hull: cannot publish the hull: ", e.what());
  }
  if (!stream_.hasHull() || !published_) {
    response.success = false;
    response.message = "no hull yet";
    return true;
  }
  try {
    const SavePaths paths = savePaths(request.path);
    writeOctomap(publishedTree(), paths.octree);
    writePly(paths.mesh, publishedMesh());
    response.success = true;
    response.message = "wrote " + paths.octree + " and " + paths.mesh;
  } catch (const std::exception& e) {
    response.success = false;
    response.message = e.what();
  }
  return true;
}

}  // namespace sift_hull
