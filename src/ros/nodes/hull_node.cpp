#include "nodes/hull_node.h"

#include <image_transport/camera_common.h>
#include <malloc.h>
#include <tf2_eigen/tf2_eigen.h>

#include <algorithm>
#include <cstdio>
#include <future>

#include "lib/conversions.h"
#include "lib/ros_params.h"
#include "sift_hull/hull/silhouette.h"

namespace sift_hull {
namespace {

constexpr double kThrottle_s = 5.0;
/// Wall time inputs may arrive without pairing before /diagnostics warns.
constexpr double kPairingPatience_s = 5.0;
/// Wall time a changed hull may wait for the queue to drain before it is published anyway.
constexpr double kMaxPublishDelay_s = 1.0;
/// Wall time between returns of freed memory to the system, when the views' queue drains.
constexpr double kTrimPeriod_s = 1.0;

}  // namespace

HullNode::HullNode(ros::NodeHandle nh, ros::NodeHandle private_nh)
    : HullNode(nh, private_nh, ros_params::readHullNodeConfig(private_nh),
               ros_params::readHullStreamConfig(private_nh)) {}

HullNode::HullNode(ros::NodeHandle nh, ros::NodeHandle private_nh, HullNodeConfig node_config,
                   HullStreamConfig hull_config)
    : nh_(nh),
      private_nh_(private_nh),
      config_(std::move(node_config)),
      skip_views_(hull_config.skip_views.begin(), hull_config.skip_views.end()),
      hull_(std::move(hull_config), config_.carving),
      points_(static_cast<size_t>(config_.queue_size)),
      start_wall_(ros::WallTime::now()),
      work_(config_.queue_size, 1,
            [this](Posed& posed) {
              integrate(posed);
              if (hull_.refining()) continueRefining();
            }),
      outputs_(nh_, config_.world_frame, &hull_.stream(),
               [this](std::function<void()> task) { return work_.post(std::move(task)); }),
      pairing_(config_.photo_carve && !config_.from_image
                   ? std::vector<std::string>{"silhouette", "camera_info", "image"}
                   : std::vector<std::string>{config_.from_image ? "image" : "silhouette",
                                              "camera_info"},
               kPairingPatience_s,
               "a silhouette pairs with the camera_info of an equal stamp once tf has its "
               "camera's pose in ~world_frame (a node making masks must copy its image's header: "
               "stamp and frame_id)"),
      tf_listener_(&tf_buffer_, "hull: "),
      pose_wait_(
          nh_, &tf_buffer_, config_.world_frame, static_cast<uint32_t>(config_.queue_size),
          config_.pose_timeout_s,
          [this](const sensor_msgs::ImageConstPtr& silhouette,
                 const sensor_msgs::CameraInfoConstPtr& info,
                 const Eigen::Isometry3d& T_W_C) { onPosed(silhouette, info, T_W_C); },
          [this](const std::string&, const std::string& why) {
            problem("hull: dropped a silhouette: ", why);  // each reason names the frame
          }),
      diagnostics_(nh_, private_nh_, "hull", config_.diagnostic_period,
                   [this](diagnostic_updater::DiagnosticStatusWrapper& status) {
                     reportDiagnostics(status);
                   }),
      image_transport_(nh_),
      sync_(config_.queue_size),
      photo_sync_(config_.queue_size) {
  if (config_.photo_carve) {
    photo_ = std::make_unique<PhotoStream>(config_.photo,
                                           [this] { work_.post([this] { takePhotoPass(); }); });
  }
  if (photo_) outputs_.colourClouds();
  startSegmentingTogether();
  outputs_.advertise();
  refine_timer_ = nh_.createWallTimer(ros::WallDuration(config_.refine_period_s),
                                      [this](const ros::WallTimerEvent&) {
                                        if (!refine_posted_.exchange(true)) {
                                          work_.post([this] { refineIfDue(); });
                                        }
                                      });
  advertiseServices();
  subscribe();
}

HullNode::~HullNode() {
  work_.stop();  // first: the worker uses what is destroyed after it; later posts are ignored
}

// --- Input (callbacks: they only take messages in) ---------------------------------------------
void HullNode::subscribe() {
  silhouette_sub_.registerCallback(&HullNode::onArrival, this);
  info_sub_.registerCallback(&HullNode::onInfoArrival, this);
  const std::string image_topic = nh_.resolveName(config_.from_image ? "image" : "silhouette");
  if (config_.photo_carve && !config_.from_image) {
    subscribePhotos(image_topic);
  } else {
    sync_.connectInput(silhouette_sub_, info_sub_);
    sync_.registerCallback(&HullNode::onPair, this);
  }
  // Surface points are looked up in tf as they come (a matcher publishes them after it has
  // looked up the same poses): one without a pose is counted at once, not kept waiting.
  points_sub_.registerCallback(&HullNode::onSurfacePoints, this);
  points_sub_.subscribe(nh_, "surface_points", static_cast<uint32_t>(config_.queue_size));
  // camera_info beside the image, wherever remapping put it (image_transport's convention);
  // the image through the transport ~image_transport names (raw, compressed, ...).
  info_sub_.subscribe(nh_, image_transport::getCameraInfoTopic(image_topic), config_.queue_size);
  silhouette_sub_.subscribe(
      image_transport_, image_topic, config_.queue_size,
      image_transport::TransportHints("raw", ros::TransportHints(), private_nh_));
}

void HullNode::onArrival(const sensor_msgs::ImageConstPtr& silhouette) {
  ++counts_.silhouettes;
  pairing_.arrived(0, silhouette->header.stamp.toSec(), PairingWatch::Clock::now());
}

void HullNode::onInfoArrival(const sensor_msgs::CameraInfoConstPtr& info) {
  pairing_.arrived(1, info->header.stamp.toSec(), PairingWatch::Clock::now());
}

void HullNode::onPair(const sensor_msgs::ImageConstPtr& silhouette,
                      const sensor_msgs::CameraInfoConstPtr& info) {
  ++counts_.paired;
  pairing_.paired();
  pose_wait_.add(silhouette, info);
}

void HullNode::onPosed(const sensor_msgs::ImageConstPtr& silhouette,
                       const sensor_msgs::CameraInfoConstPtr& info,
                       const Eigen::Isometry3d& T_W_C) {
  sensor_msgs::ImageConstPtr photo = photo_ ? takePhoto(silhouette) : nullptr;
  pushCounted(&work_, Posed{silhouette, info, T_W_C, generation_, std::move(photo)},
              "hull: views waiting to be carved (~queue_size)");
}

void HullNode::onSurfacePoints(const sift_hull::SurfacePointsConstPtr& message) {
  ++counts_.pairs;
  PosedPoints posed{message, Eigen::Isometry3d::Identity()};
  try {
    posed.T_W_F = tf2::transformToEigen(tf_buffer_.lookupTransform(
        config_.world_frame, message->header.frame_id, message->header.stamp));
  } catch (const tf2::TransformException& e) {
    ++counts_.pairs_no_pose;
    problem("hull: surface points ignored: ", e.what());
    return;
  }
  if (!points_.push(std::move(posed))) {
    ++counts_.pairs_queue_full;
    ROS_WARN_THROTTLE(kThrottle_s,
                      "hull: surface points come faster than they are taken: "
                      "the oldest pair waiting dropped (~queue_size)");
  }
  if (!points_posted_.exchange(true)) work_.post([this] { takeSurfacePoints(); });
}

// --- Work (the worker thread) ------------------------------------------------------------------
void HullNode::integrate(Posed& posed) {
  if (posed.generation != generation_) {  // queued before a ~reset
    ++counts_.reset;
    return;
  }
  const ros::WallTime start = ros::WallTime::now();
  const std_msgs::Header& header = posed.silhouette->header;
  char stamp[32];
  std::snprintf(stamp, sizeof stamp, "@%u.%09u", header.stamp.sec, header.stamp.nsec);
  if (skip_views_.count(header.frame_id + stamp) > 0) {
    ++counts_.skipped;  // one frame of a moving camera, named by its stamp
    return;
  }
  View view;
  if (!viewOf(posed, &view)) {
    ++counts_.bad;
    return;
  }
  HullStream::Outcome outcome = HullStream::Outcome::kRefused;
  bool changed = carve(view, &outcome);
  newest_view_stamp_ = std::max(newest_view_stamp_, view.stamp);
  if (together_ && together_->segmentDue(false)) changed = segmentTogether() || changed;
  if (photo_ &&
      (outcome == HullStream::Outcome::kCarved || outcome == HullStream::Outcome::kWaiting)) {
    keepPhoto(posed, view);
  }
  const ros::WallTime carved = ros::WallTime::now();
  last_carve_ms_ = (carved - start).toSec() * 1e3;
  last_view_stamp_ = view.stamp.toSec();
  if (changed) unpublished_stamp_ = view.stamp;
  // Waiting, skipped or redundant: the published hull stands. Views queued behind this one refine
  // the hull at once: each state would cost a conversion the next view replaces, so the hull is
  // published when the queue has drained, or kMaxPublishDelay_s after the last publication under
  // a stream that never lets it drain, stamped with the newest view that changed it.
  const bool drained = work_.counts().waiting == 0;
  if (drained && (carved - last_trim_wall_).toSec() > kTrimPeriod_s) {
    malloc_trim(0);  // a flood's buffers back to the system
    last_trim_wall_ = carved;
  }
  if (drained && photo_) startPhotoPass();
  if (unpublished_stamp_.isZero()) return;
  if (!drained && (ros::WallTime::now() - last_publish_wall_).toSec() < kMaxPublishDelay_s) return;
  publishPending();
  last_publish_ms_ = (ros::WallTime::now() - carved).toSec() * 1e3;
}

bool HullNode::carve(const View& view, HullStream::Outcome* outcome_out) {
  const std::string& name = view.name;
  const size_t before = hull_.stream().hasHull() ? hull_.stream().hull().views().size() : 0;
  try {
    const HullStream::Outcome outcome = hull_.add(name, view.camera, view.mask);
    *outcome_out = outcome;
    const HullStream& stream = hull_.stream();
    for (const std::string& refusal : hull_.takeRefusals()) {
      problem("hull: view refused: ", refusal);
      ++counts_.refused;
      // "view 'NAME': why": no photograph of that frame is used (a moving camera's included).
      const size_t close = refusal.find("': ");
      if (photo_ && refusal.rfind("view '", 0) == 0 && close != std::string::npos) {
        photo_->remove(refusal.substr(6, close - 6));
      }
    }
    counts_.waiting = stream.waitingViews();
    if (stream.hasHull()) counts_.carved += stream.hull().views().size() - before;
    if (outcome == HullStream::Outcome::kWaiting) {
      ROS_INFO_THROTTLE(kThrottle_s, "hull: %zu view(s) waiting for a bounding box: %s",
                        stream.waitingViews(), stream.whyNoBox().c_str());
    }
    if (outcome == HullStream::Outcome::kSkipped) ++counts_.skipped;  // as ~skip_views asks
    if (outcome == HullStream::Outcome::kRedundant) {
      ++counts_.redundant;
      ROS_INFO_THROTTLE(kThrottle_s,
                        "hull: %zu view(s) left out so far: seen from where a view already taken "
                        "was (~min_view_distance_m, ~min_view_angle_deg)",
                        stream.redundantViews());
    }
    return outcome == HullStream::Outcome::kCarved;
  } catch (const std::exception& e) {
    ++counts_.bad;
    problem("hull: view '" + name + "' ignored: ", e.what());
    return false;
  }
}

void HullNode::problem(const std::string& prefix, const std::string& why) {
  log_.error(prefix, why);
  std::lock_guard<std::mutex> lock(problem_mutex_);
  last_problem_ = prefix + why;
}

void HullNode::publishPending() {
  if (!unpublished_stamp_.isZero()) publish(unpublished_stamp_);
}

void HullNode::publish(ros::Time stamp, bool all) {
  last_publish_wall_ = ros::WallTime::now();
  unpublished_stamp_ = ros::Time();
  try {
    outputs_.publish(stamp, all);
  } catch (const std::exception& e) {  // e.g. a hull beyond OctoMap's key range
    problem("hull: cannot publish the hull: ", e.what());
  }
}

// --- Services and diagnostics (callbacks; the work on the worker) -------------------------------
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
  ++generation_;  // what is queued now is not carved, whenever the worker gets to it
  const size_t posed = work_.clear();
  const size_t waiting_pose = pose_wait_.clear();
  const size_t pairs = points_.clear();
  counts_.reset += posed + waiting_pose;
  counts_.pairs_reset += pairs;
  if (!work_.call([this] { resetOnWorker(); }, kServiceWait_s)) {
    problem("hull: ~reset: ", "the worker is busy; the hull is reset as soon as it is free");
  }
  ROS_INFO(
      "hull: reset (%zu view(s) waiting to be carved, %zu waiting for their pose and %zu "
      "pairs of surface points discarded)",
      posed, waiting_pose, pairs);
  return true;
}

void HullNode::resetOnWorker() {
  counts_.reset += hull_.stream().waitingViews();
  hull_.reset();
  if (together_) together_->clear();
  if (photo_) {
    photo_->reset();
    outputs_.setColours(nullptr, false);
    photo_views_ = 0;
    photo_views_left_out_ = 0;
    std::lock_guard<std::mutex> lock(photos_mutex_);
    photos_.clear();
  }
  counts_.free_voxels = 0;
  counts_.waiting = 0;
  publish(ros::Time::now(), true);  // the empty map and no markers, on every output
}

bool HullNode::save(sift_hull::Save::Request& request, sift_hull::Save::Response& response) {
  // Filled on the worker: a promise, so that a save that outlasts the wait writes nothing here.
  auto result = std::make_shared<std::promise<sift_hull::Save::Response>>();
  std::future<sift_hull::Save::Response> saved = result->get_future();
  const std::string path = request.path;
  work_.call([this, path, result] { result->set_value(saveOnWorker(path)); }, kSaveWait_s);
  const bool done = saved.wait_for(std::chrono::seconds(0)) == std::future_status::ready;
  if (done) response = saved.get();
  if (!done) response.message = "still saving; the node's log says when it is done";
  return true;
}

sift_hull::Save::Response HullNode::saveOnWorker(const std::string& path) {
  publishPending();  // views carved but not yet published: saved as published
  sift_hull::Save::Response response;
  response.success = outputs_.save(path, &response.message);
  if (response.success) ROS_INFO("hull: ~save %s", response.message.c_str());
  if (!response.success) problem("hull: ~save refused: ", response.message);
  return response;
}

bool HullNode::getMap(bool binary, sift_hull::GetOctomap::Response* response) {
  std::shared_ptr<const sift_hull::Octomap> map =
      binary ? outputs_.binarySnapshot() : outputs_.fullSnapshot();
  if (!map && !binary && !outputs_.keepsFullMap()) {  // the first ask: made once, then kept
    outputs_.keepFullMap();
    work_.call(
        [this] {
          publishPending();
          if (outputs_.published() && !outputs_.fullSnapshot()) publish(outputs_.header().stamp);
        },
        kServiceWait_s);
    map = outputs_.fullSnapshot();
  }
  if (!map) {
    problem(binary ? "hull: octomap_binary refused: " : "hull: octomap_full refused: ",
            "no map yet (no view carved since the start or ~reset), or the worker was busy for "
            "more than " +
                std::to_string(kServiceWait_s) + " s");
    return false;
  }
  response->map = *map;
  return true;
}

bool HullNode::clearBbx(sift_hull::BoundingBoxQuery::Request& request,
                        sift_hull::BoundingBoxQuery::Response&) {
  const Box3d box = ros_conversions::boxFromCorners(request.min, request.max);
  const std::string corners =
      ros_conversions::pointText(request.min) + " to " + ros_conversions::pointText(request.max);
  if (!isValidClearBox(box)) {
    problem("hull: ~clear_bbx refused: ",
            corners + ": the corners must be finite with min <= max on each axis");
    return false;
  }
  auto ok = std::make_shared<std::atomic<bool>>(false);
  const bool done = work_.call(
      [this, box, corners, ok] {
        publishPending();
        if (!hull_.stream().hasHull()) {
          problem("hull: ~clear_bbx refused: ", "no map yet to clear " + corners + " in");
          return;
        }
        try {
          const size_t voxels = hull_.clearBox(box);  // into the hull: every later map has it
          counts_.free_voxels = hull_.freeVoxelCount();
          publish(ros::Time::now());
          ROS_INFO("hull: ~clear_bbx: cleared %s (%zu occupied voxels)", corners.c_str(), voxels);
          *ok = true;
        } catch (const std::exception& e) {
          problem("hull: ~clear_bbx refused: ", corners + ": " + e.what());
        }
      },
      kServiceWait_s);
  if (!done)
    ROS_WARN("hull: ~clear_bbx: the worker is busy; %s is cleared once it is free",
             corners.c_str());
  return !done || *ok;
}

void HullNode::reportDiagnostics(diagnostic_updater::DiagnosticStatusWrapper& status) {
  reportQueue(work_.counts(), "views", &status);  // received, processed, dropped, waiting
  counts_.report(pose_wait_.dropped(), &status);
  status.add("last view carve ms", last_carve_ms_.load());
  status.add("last view publish ms", last_publish_ms_.load());
  status.add("carving box (m)", outputs_.carvingBoxText());  // as sift_hull hull --box takes it
  status.add("last refinement ms", last_refine_ms_.load());
  status.add("last refinement's longest slice ms", longest_refine_slice_ms_.load());
  status.add("last view stamp", last_view_stamp_.load());
  status.add("tf transforms refused", tf_listener_.refused());
  if (photo_) reportPhotoDiagnostics(status);
  if (together_) reportSegmentation(status);
  const auto warn = [&status](const std::string& text) {
    status.mergeSummary(diagnostic_msgs::DiagnosticStatus::WARN, text);
    ROS_WARN_THROTTLE(kThrottle_s, "hull: %s", text.c_str());
  };
  const std::string unpaired = pairing_.problem(PairingWatch::Clock::now());
  if (!unpaired.empty()) warn(unpaired);
  const std::string image_topic = silhouette_sub_.getTopic();
  if (counts_.silhouettes == 0 &&
      (ros::WallTime::now() - start_wall_).toSec() > kPairingPatience_s) {
    warn("nothing arrived on " + image_topic + " (and " +
         image_transport::getCameraInfoTopic(image_topic) + ") since the start: check the remaps");
  }
  std::lock_guard<std::mutex> lock(problem_mutex_);
  if (counts_.carved == 0 && counts_.silhouettes > 0 && !last_problem_.empty()) {
    warn("no view carved yet; the last problem: " + last_problem_);
  }
}

}  // namespace sift_hull
