#include "nodes/hull_node.h"

#include <image_transport/camera_common.h>
#include <tf2_eigen/tf2_eigen.h>

#include <algorithm>
#include <sstream>

#include "lib/conversions.h"
#include "lib/ros_params.h"
#include "lib/save_paths.h"
#include "sift_hull/hull/silhouette.h"
#include "sift_hull/io/ply.h"

namespace sift_hull {
namespace {

constexpr double kThrottle_s = 5.0;
/// Wall time inputs may arrive without pairing before /diagnostics warns.
constexpr double kPairingPatience_s = 5.0;
/// Wall time a changed hull may wait for the queue to drain before it is published anyway.
constexpr double kMaxPublishDelay_s = 1.0;
/// Wall time a pair's surface points may wait for the pose of their frame in tf.
constexpr double kSurfacePoseWait_s = 0.5;

std::string pointText(const geometry_msgs::Point& point) {
  std::ostringstream out;
  out << "(" << point.x << ", " << point.y << ", " << point.z << ")";
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
      hull_(std::move(hull_config), config_.carving),
      work_(config_.queue_size, 1, [this](View& view) { integrate(view); }),
      pairing_({config_.from_image ? "image" : "silhouette", "camera_info"}, kPairingPatience_s,
               "a silhouette pairs with the camera_info of an equal stamp once tf has its "
               "camera's pose in ~world_frame (a node making masks must copy its image's header: "
               "stamp and frame_id)"),
      tf_listener_(tf_buffer_),
      pose_wait_(
          nh_, &tf_buffer_, config_.world_frame, static_cast<uint32_t>(config_.queue_size),
          config_.pose_timeout_s,
          [this](const sensor_msgs::ImageConstPtr& silhouette,
                 const sensor_msgs::CameraInfoConstPtr& info,
                 const Eigen::Isometry3d& T_W_C) { onPosed(silhouette, info, T_W_C); },
          [this](const std::string&, const std::string& why) {
            log_.error("hull: dropped a silhouette: ", why);  // each reason names the frame
          }),
      diagnostics_(nh_, private_nh_, "hull", config_.diagnostic_period,
                   [this](diagnostic_updater::DiagnosticStatusWrapper& status) {
                     reportDiagnostics(status);
                   }),
      sync_(config_.queue_size) {
  advertiseOutputs();
  refine_timer_ = nh_.createWallTimer(ros::WallDuration(config_.refine_period_s),
                                      [this](const ros::WallTimerEvent&) { refineIfDue(); });
  advertiseServices();
  subscribe();
}

// --- Input -------------------------------------------------------------------------------------
void HullNode::subscribe() {
  silhouette_sub_.registerCallback(&HullNode::onArrival, this);
  info_sub_.registerCallback(&HullNode::onInfoArrival, this);
  sync_.connectInput(silhouette_sub_, info_sub_);
  sync_.registerCallback(&HullNode::onPair, this);
  surface_points_sub_ = nh_.subscribe("surface_points", static_cast<uint32_t>(config_.queue_size),
                                      &HullNode::onSurfacePoints, this);
  // camera_info beside the image, wherever remapping put it (image_transport's convention).
  const std::string image_topic = nh_.resolveName(config_.from_image ? "image" : "silhouette");
  info_sub_.subscribe(nh_, image_transport::getCameraInfoTopic(image_topic), config_.queue_size);
  silhouette_sub_.subscribe(nh_, image_topic, config_.queue_size);
}

void HullNode::onArrival(const sensor_msgs::ImageConstPtr& silhouette) {
  pairing_.arrived(0, silhouette->header.stamp.toSec(), PairingWatch::Clock::now());
}

void HullNode::onInfoArrival(const sensor_msgs::CameraInfoConstPtr& info) {
  pairing_.arrived(1, info->header.stamp.toSec(), PairingWatch::Clock::now());
}

void HullNode::onPair(const sensor_msgs::ImageConstPtr& silhouette,
                      const sensor_msgs::CameraInfoConstPtr& info) {
  pairing_.paired();
  pose_wait_.add(silhouette, info);
}

void HullNode::onPosed(const sensor_msgs::ImageConstPtr& silhouette,
                       const sensor_msgs::CameraInfoConstPtr& info,
                       const Eigen::Isometry3d& T_W_C) {
  View view;
  if (!viewOf(silhouette, *info, T_W_C, &view)) return;
  pushCounted(&work_, std::move(view), "hull: views waiting to be carved (~queue_size)");
}

bool HullNode::viewOf(const sensor_msgs::ImageConstPtr& silhouette,
                      const sensor_msgs::CameraInfo& info, const Eigen::Isometry3d& T_W_C,
                      View* view) {
  const std::string& name = silhouette->header.frame_id;
  std::string why_not;
  view->mask = config_.from_image ? ros_conversions::eightBitImage(silhouette, &why_not)
                                  : ros_conversions::maskFromImage(*silhouette, &why_not);
  if (config_.from_image && !view->mask.empty()) {
    view->mask = silhouetteFromImage(view->mask, config_.recipe);
  }
  if (view->mask.empty() ||
      !ros_conversions::cameraFromInfo(info, T_W_C, cv::Size(silhouette->width, silhouette->height),
                                       &view->camera, &why_not, config_.rectified)) {
    log_.error("hull: view '" + name + "' ignored: ", why_not);
    return false;
  }
  view->name = name;
  view->stamp = silhouette->header.stamp;
  view->generation = generation_;
  return true;
}

void HullNode::onSurfacePoints(const sift_hull::SurfacePointsConstPtr& message) {
  Eigen::Isometry3d T_W_F;
  try {
    T_W_F = tf2::transformToEigen(
        tf_buffer_.lookupTransform(config_.world_frame, message->header.frame_id,
                                   message->header.stamp, ros::Duration(kSurfacePoseWait_s)));
  } catch (const tf2::TransformException& e) {
    log_.error("hull: surface points ignored: ", "no pose of '" + message->header.frame_id +
                                                     "' in '" + config_.world_frame +
                                                     "' at their stamp (" + e.what() + ")");
    return;
  }
  PinholeCamera left, right;
  std::vector<SurfacePoint> points;
  std::string why_not;
  if (!ros_conversions::surfacePointsFromMessage(*message, T_W_F, &left, &right, &points,
                                                 &why_not)) {
    log_.error("hull: surface points ignored: ", why_not);
    return;
  }
  hull_.addSurfacePoints(left, right, std::move(points),
                         static_cast<int64_t>(message->header.stamp.toNSec()));
}

// --- Work --------------------------------------------------------------------------------------
void HullNode::integrate(View& view) {
  std::lock_guard<std::mutex> lock(hull_mutex_);
  if (view.generation != generation_) return;  // queued before a ~reset
  const ros::WallTime start = ros::WallTime::now();
  const bool changed = carve(view);
  const ros::WallTime carved = ros::WallTime::now();
  last_carve_ms_ = (carved - start).toSec() * 1e3;
  last_view_stamp_ = view.stamp.toSec();
  if (changed) unpublished_stamp_ = view.stamp;
  // Waiting, skipped or redundant: the published hull stands. Views queued behind this one refine
  // the hull at once: each state would cost a conversion the next view replaces, so the hull is
  // published when the queue has drained, or kMaxPublishDelay_s after the last publication under
  // a stream that never lets it drain, stamped with the newest view that changed it.
  if (unpublished_stamp_.isZero()) return;
  if (work_.counts().waiting > 0 &&
      (ros::WallTime::now() - last_publish_wall_).toSec() < kMaxPublishDelay_s) {
    return;
  }
  publishPending();
  last_publish_ms_ = (ros::WallTime::now() - carved).toSec() * 1e3;
}

bool HullNode::carve(const View& view) {
  const std::string& name = view.name;
  try {
    const HullStream::Outcome outcome = hull_.add(name, view.camera, view.mask);
    const HullStream& stream = hull_.stream();
    for (const std::string& refusal : hull_.takeRefusals()) {
      log_.error("hull: view refused: ", refusal);
    }
    refused_views_ = stream.refusedViews();
    redundant_views_ = stream.redundantViews();
    if (outcome == HullStream::Outcome::kWaiting) {
      ROS_INFO_THROTTLE(kThrottle_s, "hull: %zu view(s) waiting for a bounding box: %s",
                        stream.waitingViews(), stream.whyNoBox().c_str());
    }
    if (outcome == HullStream::Outcome::kSkipped) ROS_INFO("hull: view '%s' skipped", name.c_str());
    if (outcome == HullStream::Outcome::kRedundant) {
      ROS_INFO_THROTTLE(kThrottle_s,
                        "hull: %zu view(s) left out so far: seen from where a view already taken "
                        "was (~min_view_distance_m, ~min_view_angle_deg)",
                        stream.redundantViews());
    }
    return outcome == HullStream::Outcome::kCarved;
  } catch (const std::exception& e) {
    log_.error("hull: view '" + name + "' ignored: ", e.what());
    return false;
  }
}

void HullNode::refineIfDue() {
  std::lock_guard<std::mutex> lock(hull_mutex_);
  if (!hull_.refineDue()) return;
  try {
    const PointCarvedStream::Refinement refinement = hull_.refine();
    free_voxels_ = refinement.free_voxels;
    ros::Time newest;
    newest.fromNSec(static_cast<uint64_t>(refinement.newest_stamp_ns));
    publish(std::max(newest, header_.stamp));
  } catch (const std::exception& e) {
    log_.error("hull: cannot carve with the surface points: ", e.what());
  }
}

// --- Output ------------------------------------------------------------------------------------
template <typename Message>
void HullNode::addOutput(const std::string& topic, bool lazy, std::function<Message()> hull,
                         std::function<Message()> empty) {
  const size_t index = outputs_.size();
  Output output;
  output.lazy = lazy;
  // Latched, so that a later subscriber gets the newest map; the lazy ones are also sent to each
  // new subscriber, since they are built only while someone looks.
  output.pub = lazy ? nh_.advertise<Message>(
                          topic, 1,
                          [this, index](const ros::SingleSubscriberPublisher&) {
                            sendToNewSubscriber(index);
                          },
                          ros::SubscriberStatusCallback(), ros::VoidConstPtr(), true)
                    : nh_.advertise<Message>(topic, 1, true);
  output.send = [this, index, hull, empty] {
    outputs_[index].pub.publish(published_ ? hull() : empty());
  };
  outputs_.push_back(std::move(output));
}

void HullNode::advertiseOutputs() {
  using ros_conversions::octomapFullMessage;
  using ros_conversions::octomapMessage;
  using Cloud = sensor_msgs::PointCloud2;
  using Markers = visualization_msgs::MarkerArray;
  // No reallocation while a subscriber's connect callback reads an entry (nodelets spin while
  // this runs); such a callback sends nothing anyway until a hull is published.
  outputs_.reserve(7);
  const auto emptyTree = [this] { return octomap::OcTree(empty_resolution_m_); };
  const auto centres = [this] {
    return cleared_boxes_.empty() ? ros_conversions::pointCloudMessage(
                                        publishedCompact(true).occupied_centres_W, header_)
                                  : ros_conversions::occupiedCellsCloud(publishedTree(), header_);
  };
  const auto noCentres = [this, emptyTree] {
    return ros_conversions::occupiedCellsCloud(emptyTree(), header_);
  };
  addOutput<sift_hull::Octomap>(
      "octomap_binary", false,
      [this] {  // the compact map needs no OctoMap nodes, unless boxes were cleared
        return cleared_boxes_.empty() ? octomapMessage(publishedCompact(centres_wanted_), header_)
                                      : octomapMessage(publishedTree(), header_);
      },
      [this, emptyTree] { return octomapMessage(emptyTree(), header_); });
  addOutput<sift_hull::Octomap>(
      "octomap_full", true, [this] { return octomapFullMessage(publishedTree(), header_); },
      [this, emptyTree] { return octomapFullMessage(emptyTree(), header_); });
  addOutput<Cloud>("occupied_cells", true, centres, noCentres);
  outputs_.back().centres = true;
  addOutput<Cloud>("octomap_point_cloud_centers", true, centres, noCentres);
  outputs_.back().centres = true;
  addOutput<Markers>(
      "occupied_cells_vis_array", true,
      [this] { return ros_conversions::occupiedCellsMarkers(publishedTree(), header_); },
      [this] { return ros_conversions::deleteAllMarkers(header_); });
  addOutput<Markers>(
      "free_cells_vis_array", true,
      [this] { return ros_conversions::freeCellsMarkers(publishedTree(), header_); },
      [this] { return ros_conversions::deleteAllMarkers(header_); });
  addOutput<visualization_msgs::Marker>(
      "mesh", true, [this] { return ros_conversions::meshMarker(publishedMesh(), header_); },
      [this] { return ros_conversions::deleteAllMarkers(header_).markers.front(); });
  outputs_.back().map = false;
}

void HullNode::publish(const ros::Time& stamp, bool hull_changed, bool all) {
  header_.stamp = stamp;
  header_.frame_id = config_.world_frame;
  last_publish_wall_ = ros::WallTime::now();
  unpublished_stamp_ = ros::Time();
  if (hull_changed) {
    tree_.reset();
    compact_.reset();
    mesh_.reset();
  }
  published_ = hull_.stream().hasHull();
  const auto sent = [all](const Output& output) {
    return all || !output.lazy || output.pub.getNumSubscribers() > 0;
  };
  centres_wanted_ = std::any_of(outputs_.begin(), outputs_.end(),
                                [&](const Output& o) { return o.centres && sent(o); });
  for (const Output& output : outputs_) {
    if (sent(output) && (hull_changed || output.map)) output.send();
  }
}

void HullNode::publishPending() {
  if (unpublished_stamp_.isZero()) return;
  try {
    publish(unpublished_stamp_);
  } catch (const std::exception& e) {  // e.g. a hull beyond OctoMap's key range
    unpublished_stamp_ = ros::Time();
    log_.error("hull: cannot publish the hull: ", e.what());
  }
}

void HullNode::sendToNewSubscriber(size_t output) {
  std::lock_guard<std::mutex> lock(hull_mutex_);
  publishPending();  // views carved but not yet published: their map, with their stamp
  if (!published_) return;
  try {
    outputs_[output].send();
  } catch (const std::exception& e) {  // never into roscpp's callback
    log_.error("hull: cannot publish the hull: ", e.what());
  }
}

const octomap::OcTree& HullNode::publishedTree() {
  if (!tree_) {
    tree_ = toOctomap(hull_.stream().hull());
    for (const Box3d& box : cleared_boxes_) clearBox(box, tree_.get());
  }
  return *tree_;
}

const CompactOctomap& HullNode::publishedCompact(bool centres) {
  if (!compact_ || (centres && !compact_centres_)) {
    compact_ = std::make_unique<CompactOctomap>(compactOctomap(hull_.stream().hull(), centres));
    compact_centres_ = centres;
  }
  return *compact_;
}

const TriangleMesh& HullNode::publishedMesh() {
  if (!mesh_) mesh_ = std::make_unique<TriangleMesh>(hull_.stream().hull().mesh());
  return *mesh_;
}

// --- Services and diagnostics ------------------------------------------------------------------
void HullNode::advertiseServices() {
  reset_srv_ = private_nh_.advertiseService("reset", &HullNode::reset, this);
  save_srv_ = private_nh_.advertiseService("save", &HullNode::save, this);
  // octomap_server's names: the maps in the node's namespace, clearing private.
  using Request = sift_hull::GetOctomap::Request;
  using Response = sift_hull::GetOctomap::Response;
  binary_srv_ = nh_.advertiseService<Request, Response>(
      "octomap_binary", [this](Request&, Response& response) { return getMap(true, &response); });
  full_srv_ = nh_.advertiseService<Request, Response>(
      "octomap_full", [this](Request&, Response& response) { return getMap(false, &response); });
  clear_bbx_srv_ = private_nh_.advertiseService("clear_bbx", &HullNode::clearBbx, this);
}

bool HullNode::reset(std_srvs::Empty::Request&, std_srvs::Empty::Response&) {
  std::lock_guard<std::mutex> lock(hull_mutex_);
  ++generation_;
  const size_t discarded = work_.clear();  // views from before the reset
  if (hull_.stream().hasHull()) empty_resolution_m_ = hull_.stream().hull().cube().resolution_m;
  hull_.reset();
  free_voxels_ = 0;
  refused_views_ = 0;
  cleared_boxes_.clear();
  publish(ros::Time::now(), true, true);  // the empty map and no markers, on every output
  ROS_INFO("hull: reset (%zu view(s) waiting to be carved discarded)", discarded);
  return true;
}

bool HullNode::save(sift_hull::Save::Request& request, sift_hull::Save::Response& response) {
  std::lock_guard<std::mutex> lock(hull_mutex_);
  publishPending();  // views carved but not yet published: saved as published
  response.success = false;
  if (!published_) {
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
    response.message = e.what();
  }
  return true;
}

bool HullNode::getMap(bool binary, sift_hull::GetOctomap::Response* response) {
  std::lock_guard<std::mutex> lock(hull_mutex_);
  publishPending();
  if (!published_) {
    log_.error(binary ? "hull: octomap_binary refused: " : "hull: octomap_full refused: ",
               "no map yet (no view carved since the start or ~reset)");
    return false;
  }
  response->map = binary ? ros_conversions::octomapMessage(publishedTree(), header_)
                         : ros_conversions::octomapFullMessage(publishedTree(), header_);
  return true;
}

bool HullNode::clearBbx(sift_hull::BoundingBoxQuery::Request& request,
                        sift_hull::BoundingBoxQuery::Response&) {
  const Box3d box = ros_conversions::boxFromCorners(request.min, request.max);
  if (!isValidClearBox(box)) {
    log_.error("hull: ~clear_bbx refused: ", "min " + pointText(request.min) + " and max " +
                                                 pointText(request.max) +
                                                 " must be finite with min <= max on each axis");
    return false;
  }
  std::lock_guard<std::mutex> lock(hull_mutex_);
  publishPending();
  cleared_boxes_.push_back(box);  // applied to every later map too, until ~reset
  if (!published_) {
    ROS_INFO("hull: ~clear_bbx: no map yet; the box will be cleared in the first one");
    return true;
  }
  if (tree_) clearBox(box, tree_.get());  // else built with every cleared box when needed
  publish(ros::Time::now(), false);       // the maps again; the mesh is unchanged
  ROS_INFO("hull: ~clear_bbx: cleared %s to %s", pointText(request.min).c_str(),
           pointText(request.max).c_str());
  return true;
}

void HullNode::reportDiagnostics(diagnostic_updater::DiagnosticStatusWrapper& status) {
  reportQueue(work_.counts(), "views", &status);
  status.add("views redundant", redundant_views_.load());
  status.add("views refused", refused_views_.load());
  status.add("views without pose", pose_wait_.dropped());
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

}  // namespace sift_hull
