#pragma once

#include <diagnostic_updater/diagnostic_updater.h>
#include <dynamic_reconfigure/server.h>
#include <image_transport/image_transport.h>
#include <message_filters/subscriber.h>
#include <message_filters/sync_policies/approximate_time.h>
#include <message_filters/sync_policies/exact_time.h>
#include <message_filters/synchronizer.h>
#include <message_filters/time_synchronizer.h>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <tf2_ros/buffer.h>

#include <Eigen/Geometry>
#include <atomic>
#include <boost/thread/recursive_mutex.hpp>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "lib/image_input.h"
#include "lib/node_diagnostics.h"
#include "lib/pairing_watch.h"
#include "lib/pose_wait.h"
#include "lib/tf_listener.h"
#include "lib/throttled_log.h"
#include "lib/work_queue.h"
#include "nodes/matcher_node_config.h"
#include "sift_hull/Correspondences.h"
#include "sift_hull/MatcherConfig.h"
#include "sift_hull/features/feature_cache.h"
#include "sift_hull/features/matching.h"
#include "sift_hull/features/sift.h"
#include "sift_hull/filters/filter.h"
#include "sift_hull/filters/filter_result.h"
#include "sift_hull/geometry/camera.h"
#include "sift_hull/pipeline/pair_pipeline.h"
#include "sift_hull/refine/surface_points.h"

namespace sift_hull {

/// The matcher node: a left and a right image, paired by stamp, give SIFT matches and the
/// verdicts of each filter on them (`correspondences`), and, when someone subscribes, a drawing of
/// the first filter's verdicts (`matches_image`). Inputs are subscribed only while someone
/// subscribes `correspondences`, `points` or `matches_image` (image_pipeline's connect callbacks).
class MatcherNode {
 public:
  /// Reads the private parameters (ros_params.h) and subscribes.
  MatcherNode(ros::NodeHandle nh, ros::NodeHandle private_nh);
  /// With config structs, no parameter server needed. Throws std::invalid_argument for a filter
  /// name makeFilter does not know, or one this node cannot run.
  MatcherNode(ros::NodeHandle nh, ros::NodeHandle private_nh, MatcherSettings settings);

 private:
  using Image = sensor_msgs::Image;
  using ExactSync =
      message_filters::Synchronizer<message_filters::sync_policies::ExactTime<Image, Image>>;
  using ApproximateSync =
      message_filters::Synchronizer<message_filters::sync_policies::ApproximateTime<Image, Image>>;
  using Info = sensor_msgs::CameraInfo;
  using CalibratedSync = message_filters::Synchronizer<
      message_filters::sync_policies::ExactTime<Image, Image, Info, Info>>;
  using CalibratedApproximateSync = message_filters::Synchronizer<
      message_filters::sync_policies::ApproximateTime<Image, Image, Info, Info>>;
  /// Calibrated frame to frame: each frame with the camera_info of an equal stamp.
  using FrameSync = message_filters::TimeSynchronizer<Image, Info>;

  /// The pair's cameras, the left one at the origin of its own frame.
  struct StereoCameras {
    PinholeCamera left, right;
  };
  /// What pairs are matched with. dynamic_reconfigure replaces it whole, so a pair is matched
  /// with one consistent set of settings even while they change.
  struct Pipeline {
    MatcherSettings settings;
    PairPipelineConfig pair;  ///< the settings' SIFT and matching, for runPair
    std::vector<std::unique_ptr<MatchFilter>> filters;
    std::string settings_json;
  };
  /// A pair waiting for a worker; the camera_infos only with ~calibrated.
  struct Pair {
    sensor_msgs::ImageConstPtr left, right;
    sensor_msgs::CameraInfoConstPtr left_info, right_info;
    /// Calibrated frame to frame: the right (later) camera's pose in the left (keyframe) camera's
    /// frame, from the two poses in ~world_frame; then tf is not asked again.
    bool posed = false;
    Eigen::Isometry3d T_L_R = Eigen::Isometry3d::Identity();
  };
  /// Calibrated frame to frame: the frame later frames are matched with, and its pose.
  struct Keyframe {
    sensor_msgs::ImageConstPtr image;
    sensor_msgs::CameraInfoConstPtr info;
    Eigen::Isometry3d T_W_C = Eigen::Isometry3d::Identity();
  };
  /// Calibrated frame to frame: how far ahead of the node's clock a frame may be stamped.
  static constexpr double kMaxFrameAhead_s = 2.0;
  /// Calibrated frame to frame: where each frame went, every one counted once.
  struct FrameCounts {
    size_t received = 0;      ///< frames paired with their camera_info
    size_t keyframes = 0;     ///< started a keyframe (the first, or after a pause)
    size_t out_of_order = 0;  ///< stamp not after the keyframe's
    size_t skipped = 0;       ///< baseline to the keyframe below ~min_baseline_m
    size_t turned = 0;        ///< turned beyond ~max_rotation_deg: became the keyframe unmatched
    size_t paired = 0;        ///< matched with the keyframe (then became it)
    size_t unusable = 0;      ///< image, camera_info, stamp (ahead of the clock) or pose unusable

    size_t cleared = 0;  ///< waiting for their pose when the last listener left
  };

  /// Advertises the outputs, with the connect callbacks that subscribe the inputs.
  void advertise();
  /// Builds the inputs and their synchronisers, subscribing nothing.
  void setUpInputs();
  /// The synchroniser of the two images (and their camera_infos with ~calibrated), by equal
  /// stamps or, with ~approximate_sync, the nearest ones.
  void setUpSync();
  /// Subscribes the inputs while someone subscribes an output; unsubscribes when none does.
  void onOutputsChanged();
  /// Counts each input's arrivals for pairing_.
  void watchArrivals();
  void subscribeInputs();
  void unsubscribeInputs();
  std::unique_ptr<ImageInput> imageInput(const std::string& topic);
  /// Serves the run-time thresholds (cfg/Matcher.cfg), starting from the node's own settings.
  void serveReconfigure();
  void onReconfigure(sift_hull::MatcherConfig& config, uint32_t level);
  void onPair(const sensor_msgs::ImageConstPtr& left, const sensor_msgs::ImageConstPtr& right);
  void onFrame(const sensor_msgs::ImageConstPtr& frame);
  /// Calibrated frame to frame: a frame and its camera_info, on to pose_wait_.
  void onCalibratedFrame(const sensor_msgs::ImageConstPtr& frame,
                         const sensor_msgs::CameraInfoConstPtr& info);
  /// Why a calibrated frame cannot be matched (its image, its camera_info, a stamp more than
  /// kMaxFrameAhead_s ahead of the node's clock); empty when it can.
  std::string unusableFrame(const Image& frame, const Info& info) const;
  /// A frame with its camera pose: skipped, matched with the keyframe, or made the keyframe.
  void onPosedFrame(const sensor_msgs::ImageConstPtr& frame,
                    const sensor_msgs::CameraInfoConstPtr& info, const Eigen::Isometry3d& T_W_C);
  /// Calibrated frame to frame: the wait for each frame's pose; otherwise none.
  std::unique_ptr<PoseWait> makePoseWait();
  bool calibratedFrames() const {
    return settings_.node.frame_to_frame && settings_.node.calibrated;
  }
  void onCalibratedPair(const sensor_msgs::ImageConstPtr& left,
                        const sensor_msgs::ImageConstPtr& right,
                        const sensor_msgs::CameraInfoConstPtr& left_info,
                        const sensor_msgs::CameraInfoConstPtr& right_info);
  void enqueue(Pair pair);
  void waitForTransform(const std::string& target, const std::string& source,
                        const ros::Time& stamp) const;
  void matchPair(Pair& pair);
  /// The pair through the core pipeline (runPair: SIFT through features_, matching, the
  /// filters, the first filter's kept matches triangulated), then published.
  void process(const Pipeline& pipeline, const sensor_msgs::ImageConstPtr& left,
               const sensor_msgs::ImageConstPtr& right, const StereoCameras* cameras);
  std::shared_ptr<const Pipeline> pipeline() const;
  void reportDiagnostics(diagnostic_updater::DiagnosticStatusWrapper& status);
  /// Once a second: when pairs were handled since the last time and none waits, returns the
  /// freed heap to the system (malloc_trim), so that the resident set falls back after a flood.
  void trimAfterWork();
  bool stereoCameras(const Image& left, const Image& right, const Info& left_info,
                     const Info& right_info, StereoCameras* cameras);
  /// The two cameras from their camera_infos, the right one at T_L_R in the left's frame.
  bool posedCameras(const Image& left, const Image& right, const Info& left_info,
                    const Info& right_info, const Eigen::Isometry3d& T_L_R, StereoCameras* cameras);
  /// The right camera's pose in the left camera's frame from tf.
  bool rightPoseFromTf(const Image& left, const Image& right, Eigen::Isometry3d* T_L_R);
  /// The first filter's kept matches triangulated (in the left camera's frame): `points`, and
  /// `surface_points` when someone subscribes it.
  void publishPoints(const std_msgs::Header& header, const StereoCameras& cameras,
                     const std::vector<SurfacePoint>& points);

  // Destroyed bottom up: subscriptions first, then the workers, then what they publish with.
  ros::NodeHandle nh_, private_nh_;
  const MatcherSettings settings_;  ///< as started; the reconfigurable part lives in pipeline_
  mutable std::mutex pipeline_mutex_;
  std::shared_ptr<const Pipeline> pipeline_;
  ThrottledLog log_;
  image_transport::ImageTransport transport_;
  std::mutex connect_mutex_;  ///< the outputs' connect callbacks against each other
  bool inputs_subscribed_ = false;
  ros::Publisher correspondences_pub_, points_pub_, surface_points_pub_;
  image_transport::Publisher matches_image_pub_;
  tf2_ros::Buffer tf_buffer_;
  TfListener tf_listener_;
  std::atomic<double> last_pair_ms_{0.0};
  /// Each image's features for the next pair it is in (keyed by its pixels): frame to frame and
  /// the (k, k+1) pairs of a stereo sequence describe an image once.
  FeatureCache features_{8};
  WorkQueue<Pair> work_;
  PairingWatch pairing_;  ///< images (and camera_infos) that arrive but do not pair
  // Calibrated frame to frame: after work_ (pose_wait_ queues pairs there), before diagnostics_
  // (which reads them), the keyframe before pose_wait_ (which hands it frames).
  std::mutex keyframe_mutex_;  ///< keyframe_ and frame_counts_
  Keyframe keyframe_;
  FrameCounts frame_counts_;
  std::unique_ptr<PoseWait> pose_wait_;
  NodeDiagnostics diagnostics_;
  boost::recursive_mutex reconfigure_mutex_;  // the server's, so updateConfig cannot race it
  std::unique_ptr<dynamic_reconfigure::Server<sift_hull::MatcherConfig>> reconfigure_;
  ros::WallTimer trim_timer_;
  uint64_t trimmed_after_ = 0;  ///< pairs handled at the last trim (the timer's thread only)
  std::unique_ptr<ImageInput> left_sub_, right_sub_, frame_sub_;
  sensor_msgs::ImageConstPtr previous_frame_;
  std::unique_ptr<ExactSync> exact_sync_;
  std::unique_ptr<ApproximateSync> approximate_sync_;
  message_filters::Subscriber<Info> left_info_sub_, right_info_sub_;
  std::unique_ptr<CalibratedSync> calibrated_sync_;
  std::unique_ptr<CalibratedApproximateSync> calibrated_approximate_sync_;
  // Calibrated frame to frame: the synchroniser feeding pose_wait_.
  message_filters::Subscriber<Info> frame_info_sub_;
  std::unique_ptr<FrameSync> frame_sync_;
};

}  // namespace sift_hull
