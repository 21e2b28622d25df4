#include "nodes/matcher_node.h"

#include <cv_bridge/cv_bridge.h>
#include <image_transport/camera_common.h>
#include <malloc.h>
#include <tf2_eigen/tf2_eigen.h>

#include <algorithm>
#include <cmath>
#include <utility>

#include "lib/conversions.h"
#include "lib/node_diagnostics.h"
#include "lib/reconfigure_settings.h"
#include "lib/ros_params.h"
#include "lib/wall_wait.h"
#include "sift_hull/draw/match_drawing.h"
#include "sift_hull/filters/filter.h"
#include "sift_hull/filters/filter_result.h"
#include "sift_hull/pipeline/pair_pipeline.h"

namespace sift_hull {
namespace {

/// Wall time inputs may arrive without pairing before /diagnostics warns.
constexpr double kPairingPatience_s = 5.0;

/// The inputs a synchronizer pairs (none frame to frame), for PairingWatch.
std::vector<std::string> pairedInputs(const MatcherNodeConfig& config) {
  if (config.frame_to_frame && config.calibrated) return {"image", "camera_info"};
  if (config.frame_to_frame) return {};
  if (!config.calibrated) return {"left/image", "right/image"};
  return {"left/image", "right/image", "left/camera_info", "right/camera_info"};
}

/// What pairing needs, for the warning.
std::string pairingHint(const MatcherNodeConfig& config) {
  if (config.frame_to_frame) {
    return "each frame pairs with the camera_info of an equal stamp beside it (the image's "
           "namespace + camera_info)";
  }
  if (config.approximate_sync) return "approximate sync found no stamps near enough";
  if (config.calibrated) {
    return "the two images and the camera_info beside each (the image's namespace + camera_info) "
           "pair by equal stamps (~approximate_sync: true pairs the nearest ones)";
  }
  return "the left and right images pair by equal stamps (~approximate_sync: true pairs the "
         "nearest ones)";
}

/// SIFT and matching as the settings say, every descriptor matched (no guided matching).
PairPipelineConfig pairConfig(const MatcherSettings& settings) {
  PairPipelineConfig config;
  config.sift = settings.sift;
  config.matching = settings.matching;
  return config;
}

std::vector<std::unique_ptr<MatchFilter>> makeFilters(const MatcherSettings& settings) {
  std::vector<std::unique_ptr<MatchFilter>> filters;
  for (const std::string& spec : settings.node.filters) {
    if (spec.find("epipolar") != std::string::npos && !settings.node.calibrated) {
      throw std::invalid_argument("filter '" + spec +
                                  "': the epipolar filter needs ~calibrated: true (camera_info "
                                  "of both images and tf between their frames)");
    }
    filters.push_back(makeFilter(spec, settings.filters));
  }
  if (filters.empty()) throw std::invalid_argument("~filters names no filter");
  return filters;
}

}  // namespace

MatcherNode::MatcherNode(ros::NodeHandle nh, ros::NodeHandle private_nh)
    : MatcherNode(nh, private_nh, ros_params::readMatcherSettings(private_nh)) {}

MatcherNode::MatcherNode(ros::NodeHandle nh, ros::NodeHandle private_nh, MatcherSettings settings)
    : nh_(nh),
      private_nh_(private_nh),
      settings_(std::move(settings)),
      pipeline_(std::make_shared<const Pipeline>(
          Pipeline{settings_, pairConfig(settings_), makeFilters(settings_),
                   ros_conversions::settingsJson(settings_.matching, settings_.filters)})),
      transport_(nh_),
      tf_listener_(&tf_buffer_, "matcher: "),
      work_(settings_.node.max_waiting_pairs, settings_.node.workers,
            [this](Pair& pair) { matchPair(pair); }),
      pairing_(pairedInputs(settings_.node), kPairingPatience_s, pairingHint(settings_.node)),
      pose_wait_(makePoseWait()),
      diagnostics_(nh_, private_nh_, "matcher", settings_.node.diagnostic_period,
                   [this](diagnostic_updater::DiagnosticStatusWrapper& status) {
                     reportDiagnostics(status);
                   }) {
  serveReconfigure();
  setUpInputs();
  advertise();
  trim_timer_ = nh_.createWallTimer(ros::WallDuration(1.0),
                                    [this](const ros::WallTimerEvent&) { trimAfterWork(); });
}

void MatcherNode::trimAfterWork() {
  const WorkCounts counts = work_.counts();
  const uint64_t handled = counts.done + counts.dropped;
  if (counts.waiting > 0 || handled == trimmed_after_) return;
  trimmed_after_ = handled;
  malloc_trim(0);  // the pairs' buffers (SIFT's pyramids above all) back to the system
}

void MatcherNode::advertise() {
  // Held so that a connect callback cannot see a publisher half made.
  std::lock_guard<std::mutex> lock(connect_mutex_);
  const ros::SubscriberStatusCallback changed = [this](const ros::SingleSubscriberPublisher&) {
    onOutputsChanged();
  };
  const image_transport::SubscriberStatusCallback image_changed =
      [this](const image_transport::SingleSubscriberPublisher&) { onOutputsChanged(); };
  correspondences_pub_ = nh_.advertise<sift_hull::Correspondences>(
      "correspondences", settings_.node.queue_size, changed, changed);
  matches_image_pub_ = transport_.advertise("matches_image", 1, image_changed, image_changed);
  if (settings_.node.calibrated) {
    points_pub_ = nh_.advertise<sensor_msgs::PointCloud2>("points", 1, changed, changed);
    surface_points_pub_ = nh_.advertise<sift_hull::SurfacePoints>(
        "surface_points", settings_.node.queue_size, changed, changed);
  }
}

void MatcherNode::onOutputsChanged() {
  std::lock_guard<std::mutex> lock(connect_mutex_);
  const bool wanted =
      correspondences_pub_.getNumSubscribers() > 0 || points_pub_.getNumSubscribers() > 0 ||
      surface_points_pub_.getNumSubscribers() > 0 || matches_image_pub_.getNumSubscribers() > 0;
  if (wanted == inputs_subscribed_) return;
  try {
    wanted ? subscribeInputs() : unsubscribeInputs();
  } catch (const std::runtime_error& e) {
    log_.error("matcher: cannot subscribe the images: ", e.what());
    unsubscribeInputs();
    return;
  }
  inputs_subscribed_ = wanted;
}

std::shared_ptr<const MatcherNode::Pipeline> MatcherNode::pipeline() const {
  std::lock_guard<std::mutex> lock(pipeline_mutex_);
  return pipeline_;
}

void MatcherNode::reportDiagnostics(diagnostic_updater::DiagnosticStatusWrapper& status) {
  reportQueue(work_.counts(), "pairs", &status);
  if (pose_wait_) {  // calibrated frame to frame
    // Every frame paired with its camera_info is in exactly one of these, or still waiting for
    // its pose: received = keyframes + out of order + skipped + turned + paired + unusable +
    // without pose + cleared + waiting.
    FrameCounts counts;
    {
      std::lock_guard<std::mutex> lock(keyframe_mutex_);
      counts = frame_counts_;
    }
    status.add("frames received", counts.received);
    status.add("frames without pose", pose_wait_->dropped());
    status.add("frames started a keyframe", counts.keyframes);
    status.add("frames out of order", counts.out_of_order);
    status.add("frames skipped (baseline below ~min_baseline_m)", counts.skipped);
    status.add("frames turned beyond ~max_rotation_deg", counts.turned);
    status.add("frames matched with the keyframe", counts.paired);
    status.add("frames unusable", counts.unusable);
    status.add("frames cleared waiting for their pose", counts.cleared);
  }
  for (const PairingWatch::Total& total : pairing_.totals()) {
    status.add(total.name + " received", total.received);
    status.add(total.name + " unpaired", total.unpaired);  // dropped by the synchroniser, waiting
  }
  status.add("last pair ms", last_pair_ms_.load());
  status.add("tf transforms refused", tf_listener_.refused());
  status.add("images described", features_.misses());
  status.add("features reused", features_.hits());
  const std::string unpaired = pairing_.problem(PairingWatch::Clock::now());
  if (!unpaired.empty()) {
    status.mergeSummary(diagnostic_msgs::DiagnosticStatus::WARN, unpaired);
    ROS_WARN_THROTTLE(5.0, "matcher: %s", unpaired.c_str());
  }
}

void MatcherNode::serveReconfigure() {
  sift_hull::MatcherConfig config = sift_hull::MatcherConfig::__getDefault__();
  dynamic_reconfigure::Config message =
      ros_conversions::reconfigureMessage(settingsOf<MatcherSettings>(), settings_);
  config.__fromMessage__(message);
  reconfigure_ = std::make_unique<dynamic_reconfigure::Server<sift_hull::MatcherConfig>>(
      reconfigure_mutex_, private_nh_);
  reconfigure_->updateConfig(config);
  reconfigure_->setCallback(
      [this](sift_hull::MatcherConfig& changed, uint32_t level) { onReconfigure(changed, level); });
}

void MatcherNode::onReconfigure(sift_hull::MatcherConfig& config, uint32_t) {
  const MatcherSettings current = pipeline()->settings;
  MatcherSettings changed = current;
  std::shared_ptr<const Pipeline> replacement;
  try {
    dynamic_reconfigure::Config message;
    config.__toMessage__(message);
    ros_conversions::applyReconfigure(settingsOf<MatcherSettings>(), message, &changed);
    validate(changed.matching);
    validate(changed.filters);
    replacement = std::make_shared<const Pipeline>(
        Pipeline{changed, pairConfig(changed), makeFilters(changed),
                 ros_conversions::settingsJson(changed.matching, changed.filters)});
  } catch (const std::invalid_argument& e) {
    log_.error("matcher: reconfiguration refused: ", e.what());
    // The server publishes what the callback leaves in `config`: the settings in force.
    dynamic_reconfigure::Config in_force =
        ros_conversions::reconfigureMessage(settingsOf<MatcherSettings>(), current);
    config.__fromMessage__(in_force);
    return;
  }
  std::lock_guard<std::mutex> lock(pipeline_mutex_);
  pipeline_ = std::move(replacement);
}

std::unique_ptr<ImageInput> MatcherNode::imageInput(const std::string& topic) {
  return std::make_unique<ImageInput>(transport_, nh_, private_nh_, topic,
                                      settings_.node.queue_size, settings_.node.image_transport);
}

std::unique_ptr<PoseWait> MatcherNode::makePoseWait() {
  if (!calibratedFrames()) return nullptr;
  return std::make_unique<PoseWait>(
      nh_, &tf_buffer_, settings_.node.world_frame,
      static_cast<uint32_t>(settings_.node.queue_size), settings_.node.pose_timeout_s,
      [this](const sensor_msgs::ImageConstPtr& frame, const sensor_msgs::CameraInfoConstPtr& info,
             const Eigen::Isometry3d& T_W_C) { onPosedFrame(frame, info, T_W_C); },
      [this](const std::string&, const std::string& why) {
        log_.error("matcher: frame dropped: ", why);  // each reason names the frame
      });
}

void MatcherNode::setUpInputs() {
  if (calibratedFrames()) {
    frame_sub_ = imageInput("image");
    using ImageCallback = boost::function<void(const sensor_msgs::ImageConstPtr&)>;
    using InfoCallback = boost::function<void(const sensor_msgs::CameraInfoConstPtr&)>;
    frame_sub_->registerCallback(ImageCallback([this](const sensor_msgs::ImageConstPtr& m) {
      pairing_.arrived(0, m->header.stamp.toSec(), PairingWatch::Clock::now());
    }));
    frame_info_sub_.registerCallback(InfoCallback([this](const sensor_msgs::CameraInfoConstPtr& m) {
      pairing_.arrived(1, m->header.stamp.toSec(), PairingWatch::Clock::now());
    }));
    frame_sync_ = std::make_unique<FrameSync>(static_cast<uint32_t>(settings_.node.queue_size));
    frame_sync_->connectInput(*frame_sub_, frame_info_sub_);
    frame_sync_->registerCallback(&MatcherNode::onCalibratedFrame, this);
    return;
  }
  if (settings_.node.frame_to_frame) {
    frame_sub_ = imageInput("image");
    frame_sub_->registerCallback(&MatcherNode::onFrame, this);
    return;
  }
  left_sub_ = imageInput("left/image");
  right_sub_ = imageInput("right/image");
  watchArrivals();
  setUpSync();
}

void MatcherNode::setUpSync() {
  namespace policies = message_filters::sync_policies;
  const int queue = settings_.node.queue_size;
  if (settings_.node.calibrated && settings_.node.approximate_sync) {
    calibrated_approximate_sync_ = std::make_unique<CalibratedApproximateSync>(
        policies::ApproximateTime<Image, Image, Info, Info>(queue), *left_sub_, *right_sub_,
        left_info_sub_, right_info_sub_);
    calibrated_approximate_sync_->registerCallback(&MatcherNode::onCalibratedPair, this);
  } else if (settings_.node.calibrated) {
    calibrated_sync_ =
        std::make_unique<CalibratedSync>(policies::ExactTime<Image, Image, Info, Info>(queue),
                                         *left_sub_, *right_sub_, left_info_sub_, right_info_sub_);
    calibrated_sync_->registerCallback(&MatcherNode::onCalibratedPair, this);
  } else if (settings_.node.approximate_sync) {
    approximate_sync_ = std::make_unique<ApproximateSync>(
        policies::ApproximateTime<Image, Image>(queue), *left_sub_, *right_sub_);
    approximate_sync_->registerCallback(&MatcherNode::onPair, this);
  } else {
    exact_sync_ = std::make_unique<ExactSync>(policies::ExactTime<Image, Image>(queue), *left_sub_,
                                              *right_sub_);
    exact_sync_->registerCallback(&MatcherNode::onPair, this);
  }
}

void MatcherNode::watchArrivals() {
  const auto arrived = [this](size_t input, const ros::Time& stamp) {
    pairing_.arrived(input, stamp.toSec(), PairingWatch::Clock::now());
  };
  using ImageCallback = boost::function<void(const sensor_msgs::ImageConstPtr&)>;
  using InfoCallback = boost::function<void(const sensor_msgs::CameraInfoConstPtr&)>;
  left_sub_->registerCallback(ImageCallback(
      [arrived](const sensor_msgs::ImageConstPtr& m) { arrived(0, m->header.stamp); }));
  right_sub_->registerCallback(ImageCallback(
      [arrived](const sensor_msgs::ImageConstPtr& m) { arrived(1, m->header.stamp); }));
  left_info_sub_.registerCallback(InfoCallback(
      [arrived](const sensor_msgs::CameraInfoConstPtr& m) { arrived(2, m->header.stamp); }));
  right_info_sub_.registerCallback(InfoCallback(
      [arrived](const sensor_msgs::CameraInfoConstPtr& m) { arrived(3, m->header.stamp); }));
}

void MatcherNode::subscribeInputs() {
  if (calibratedFrames()) {
    frame_sub_->subscribe();
    frame_info_sub_.subscribe(nh_, image_transport::getCameraInfoTopic(frame_sub_->resolvedTopic()),
                              static_cast<uint32_t>(settings_.node.queue_size));
    return;
  }
  if (frame_sub_) return frame_sub_->subscribe();
  left_sub_->subscribe();
  right_sub_->subscribe();
  if (!settings_.node.calibrated) return;
  // camera_info beside each image, wherever remapping put it (image_transport's convention).
  const int queue = settings_.node.queue_size;
  left_info_sub_.subscribe(nh_, image_transport::getCameraInfoTopic(left_sub_->resolvedTopic()),
                           queue);
  right_info_sub_.subscribe(nh_, image_transport::getCameraInfoTopic(right_sub_->resolvedTopic()),
                            queue);
}

void MatcherNode::unsubscribeInputs() {
  for (ImageInput* input : {frame_sub_.get(), left_sub_.get(), right_sub_.get()}) {
    if (input != nullptr) input->unsubscribe();
  }
  left_info_sub_.unsubscribe();
  right_info_sub_.unsubscribe();
  frame_info_sub_.unsubscribe();
  previous_frame_.reset();  // frame to frame: no pairing across a pause without listeners
  if (pose_wait_) {
    const size_t cleared = pose_wait_->clear();
    std::lock_guard<std::mutex> lock(keyframe_mutex_);
    frame_counts_.cleared += cleared;
    keyframe_ = Keyframe{};  // the next frame starts a new keyframe
  }
}

void MatcherNode::onFrame(const sensor_msgs::ImageConstPtr& frame) {
  if (previous_frame_ && frame->header.stamp <= previous_frame_->header.stamp) {
    log_.error("matcher: frame ignored: ", "its stamp is not after the previous frame's");
    return;
  }
  if (previous_frame_) enqueue({previous_frame_, frame, nullptr, nullptr});
  previous_frame_ = frame;
}

void MatcherNode::onPair(const sensor_msgs::ImageConstPtr& left,
                         const sensor_msgs::ImageConstPtr& right) {
  pairing_.paired();
  enqueue({left, right, nullptr, nullptr});
}

void MatcherNode::enqueue(Pair pair) {
  // Checked on arrival, from the headers alone, so that oversized images never reach a worker.
  const size_t max_pixels = pipeline()->settings.sift.max_image_pixels;
  std::string why_not;
  if (!ros_conversions::withinPixelLimit(*pair.left, max_pixels, &why_not) ||
      !ros_conversions::withinPixelLimit(*pair.right, max_pixels, &why_not)) {
    log_.error("matcher: pair ignored: ", why_not);
    return;
  }
  pushCounted(&work_, std::move(pair), "matcher: pairs waiting for a worker (~max_waiting_pairs)");
}

/// Up to 0.5 s of wall time for tf to catch up: tf2's own timeout sleeps in ROS time, which never
/// passes once a bag's clock has stopped.
void MatcherNode::waitForTransform(const std::string& target, const std::string& source,
                                   const ros::Time& stamp) const {
  waitOnWallClock([&] { return tf_buffer_.canTransform(target, source, stamp); }, 0.5, 0.01);
}

void MatcherNode::matchPair(Pair& pair) {
  const ros::WallTime start = ros::WallTime::now();
  try {
    StereoCameras cameras;
    const bool calibrated = pair.left_info && pair.right_info;
    if (calibrated && pair.posed) {
      // Calibrated frame to frame: the relative pose came with the pair.
      if (!posedCameras(*pair.left, *pair.right, *pair.left_info, *pair.right_info, pair.T_L_R,
                        &cameras)) {
        return;
      }
    } else if (calibrated && !stereoCameras(*pair.left, *pair.right, *pair.left_info,
                                            *pair.right_info, &cameras)) {
      return;
    }
    process(*pipeline(), pair.left, pair.right, calibrated ? &cameras : nullptr);
  } catch (const std::exception& e) {
    log_.error("matcher: pair failed: ", e.what());
  }
  last_pair_ms_ = (ros::WallTime::now() - start).toSec() * 1e3;
}

void MatcherNode::process(const Pipeline& pipeline, const sensor_msgs::ImageConstPtr& left,
                          const sensor_msgs::ImageConstPtr& right, const StereoCameras* cameras) {
  std::string why_not;
  PairInput input;
  input.left_image = ros_conversions::eightBitImage(left, &why_not);
  if (!input.left_image.empty())
    input.right_image = ros_conversions::eightBitImage(right, &why_not);
  if (input.left_image.empty() || input.right_image.empty()) {
    log_.error("matcher: pair ignored: ", why_not);
    return;
  }
  if (cameras != nullptr) input.cameras = std::make_pair(cameras->left, cameras->right);
  const PairResult pair =
      runPair(input, pipeline.pair, filterPointers(pipeline.filters), &features_);
  if (!pair.why_not.empty()) {
    log_.error("matcher: pair ignored: ", pair.why_not);
    return;
  }
  std::vector<std::string> names;
  std::vector<FilterResult> results;
  for (const FilterVerdicts& verdicts : pair.verdicts) {
    names.push_back(verdicts.name);
    results.push_back(verdicts.result);
  }
  correspondences_pub_.publish(ros_conversions::correspondencesMessage(
      left->header, right->header, names, pipeline.settings_json, pair.putative, results));
  if (cameras != nullptr) publishPoints(left->header, *cameras, pair.surface_points);
  if (matches_image_pub_.getNumSubscribers() > 0) {
    const cv::Mat drawing =
        drawMatchDecisions(input.left_image, input.right_image, pair.putative, results.front());
    matches_image_pub_.publish(cv_bridge::CvImage(left->header, "bgr8", drawing).toImageMsg());
  }
}

void MatcherNode::publishPoints(const std_msgs::Header& header, const StereoCameras& cameras,
                                const std::vector<SurfacePoint>& points) {
  std::vector<Eigen::Vector3d> points_L;
  for (const SurfacePoint& point : points) points_L.push_back(point.X_W);
  points_pub_.publish(ros_conversions::pointCloudMessage(points_L, header));
  if (surface_points_pub_.getNumSubscribers() == 0) return;
  surface_points_pub_.publish(
      ros_conversions::surfacePointsMessage(header, cameras.left, cameras.right, points));
}

}  // namespace sift_hull
