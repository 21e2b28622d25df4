#include "lib/result_saver.h"

#include <cv_bridge/cv_bridge.h>
#include <pcl/io/pcd_io.h>
#include <pcl/point_types.h>
#include <pcl_conversions/pcl_conversions.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>

#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <vector>

#include "lib/bag_topics.h"
#include "sift_hull/Save.h"

namespace sift_hull {

template <>
const SettingTable<ResultSaverConfig>& settingsOf<ResultSaverConfig>() {
  static const SettingTable<ResultSaverConfig> table = [] {
    SettingTable<ResultSaverConfig> t;
    t.add("bag", &ResultSaverConfig::bag, "",
          "the bag being played (written by sift_hull_ros bag); required");
    t.add("out_dir", &ResultSaverConfig::out_dir, "",
          "where the results are written (created if missing); required");
    t.add("hull_save_service", &ResultSaverConfig::hull_save_service, "",
          "hull_node's save service, called at the end");
    t.add("timeout_s", &ResultSaverConfig::timeout_s, "s",
          "give up waiting this long after start (wall time) and save what there is")
        .above(0.0);
    t.add("end_launch", &ResultSaverConfig::end_launch, "",
          "once every view and pair is saved, end the roslaunch that started this node, as Ctrl-C "
          "does (incomplete results end it by the node's exit)");
    return t;
  }();
  return table;
}

BagEnd readBagEnd(const std::string& bag_path) {
  rosbag::Bag bag(bag_path, rosbag::bagmode::Read);
  BagEnd end;
  const std::vector<std::string> topics = {bag_topics::kSilhouette, bag_topics::kLeftImage};
  rosbag::View view(bag, rosbag::TopicQuery(topics));
  for (const rosbag::MessageInstance& instance : view) {
    const sensor_msgs::ImageConstPtr image = instance.instantiate<sensor_msgs::Image>();
    if (!image) continue;
    if (instance.getTopic() == bag_topics::kSilhouette) {
      ++end.views;
      end.last_view = std::max(end.last_view, image->header.stamp);
    } else {
      ++end.pairs;
      end.last_pair = std::max(end.last_pair, image->header.stamp);
    }
  }
  return end;
}

ResultSaver::ResultSaver(ros::NodeHandle nh, ResultSaverConfig config, BagEnd bag_end)
    : nh_(nh), config_(std::move(config)), bag_end_(bag_end) {
  // Queues long enough that no output is lost while this node waits for its next spin.
  octomap_sub_ = nh_.subscribe("octomap_binary", 100, &ResultSaver::onOctomap, this);
  cloud_sub_ = nh_.subscribe("occupied_cells", 100, &ResultSaver::onCloud, this);
  correspondences_sub_ =
      nh_.subscribe("correspondences", 100, &ResultSaver::onCorrespondences, this);
  matches_image_sub_ = nh_.subscribe("matches_image", 100, &ResultSaver::onMatchesImage, this);
  diagnostics_sub_ = nh_.subscribe("/diagnostics", 100, &ResultSaver::onDiagnostics, this);
}

namespace {

/// Keeps the message with the newest stamp: with several matcher workers, outputs can come out of
/// stamp order.
template <typename Ptr>
void keepNewest(const Ptr& message, Ptr* kept) {
  if (!*kept || message->header.stamp >= (*kept)->header.stamp) *kept = message;
}

}  // namespace

void ResultSaver::onOctomap(const sift_hull::OctomapConstPtr& message) {
  ++hull_updates_;
  keepNewest(message, &octomap_);
}

void ResultSaver::onCloud(const sensor_msgs::PointCloud2ConstPtr& message) {
  keepNewest(message, &cloud_);
}

void ResultSaver::onCorrespondences(const sift_hull::CorrespondencesConstPtr& message) {
  ++pairs_matched_;
  keepNewest(message, &correspondences_);
}

void ResultSaver::onMatchesImage(const sensor_msgs::ImageConstPtr& message) {
  keepNewest(message, &matches_image_);
}

void ResultSaver::onDiagnostics(const diagnostic_msgs::DiagnosticArrayConstPtr& array) {
  const std::string task = ": hull";
  for (const diagnostic_msgs::DiagnosticStatus& status : array->status) {
    const std::string& name = status.name;
    if (name.size() < task.size() || name.compare(name.size() - task.size(), task.size(), task)) {
      continue;
    }
    for (const diagnostic_msgs::KeyValue& pair : status.values) {
      if (pair.key == "last view stamp") hull_last_view_s_ = std::stod(pair.value);
    }
  }
}

bool ResultSaver::complete() const {
  const auto reached = [](const auto& message, const ros::Time& stamp) {
    return message && message->header.stamp >= stamp;
  };
  // A last view that changes nothing (redundant, say) brings no new octomap: the hull node's
  // diagnostics then tell that it was processed.
  const bool hull_processed_last_view =
      (reached(octomap_, bag_end_.last_view) && reached(cloud_, bag_end_.last_view)) ||
      (octomap_ && cloud_ && hull_last_view_s_ >= bag_end_.last_view.toSec() - 1e-6);
  const bool hull_done = bag_end_.views == 0 || hull_processed_last_view;
  const bool matches_done = bag_end_.pairs == 0 || (reached(correspondences_, bag_end_.last_pair) &&
                                                    reached(matches_image_, bag_end_.last_pair));
  return hull_done && matches_done;
}

std::string ResultSaver::saveHull() const {
  sift_hull::Save save;
  save.request.path = config_.out_dir + "/hull";
  if (!ros::service::waitForService(config_.hull_save_service, ros::Duration(5.0))) {
    return "";
  }
  if (!ros::service::call(config_.hull_save_service, save) || !save.response.success) {
    ROS_ERROR("save_results: %s failed: %s", config_.hull_save_service.c_str(),
              save.response.message.c_str());
    return "";
  }
  return save.request.path;
}

std::string ResultSaver::saveCloud() const {
  if (!cloud_) return "";
  // Every field the cloud has: x, y, z, and rgb (PCL's PointXYZRGB) with ~photo_carve.
  pcl::PCLPointCloud2 cloud;
  pcl_conversions::toPCL(*cloud_, cloud);
  const std::string path = config_.out_dir + "/occupied_cells.pcd";
  if (cloud.width * cloud.height == 0 ||
      pcl::io::savePCDFile(path, cloud, Eigen::Vector4f::Zero(), Eigen::Quaternionf::Identity(),
                           true) != 0) {
    return "";
  }
  return path;
}

std::string ResultSaver::saveMatchesImage() const {
  if (!matches_image_) return "";
  const std::string path = config_.out_dir + "/matches.png";
  const cv_bridge::CvImageConstPtr image = cv_bridge::toCvShare(matches_image_, "bgr8");
  return cv::imwrite(path, image->image) ? path : "";
}

nlohmann::json ResultSaver::matchSummary() const {
  nlohmann::json summary = {{"pairs_in_bag", bag_end_.pairs}, {"pairs_matched", pairs_matched_}};
  if (!correspondences_) return summary;
  nlohmann::json kept = nlohmann::json::object();
  for (size_t f = 0; f < correspondences_->filters.size(); ++f) {
    int count = 0;
    for (const sift_hull::Correspondence& match : correspondences_->matches) {
      count += (match.kept_by >> f) & 1u;
    }
    kept[correspondences_->filters[f]] = count;
  }
  summary["last_pair"] = {{"matches", correspondences_->matches.size()}, {"kept", kept}};
  return summary;
}

nlohmann::json ResultSaver::save() {
  std::filesystem::create_directories(config_.out_dir);
  const std::string hull = saveHull();
  nlohmann::json summary = {{"complete", complete()},
                            {"hull",
                             {{"views_in_bag", bag_end_.views},
                              {"updates", hull_updates_},
                              {"resolution_m", octomap_ ? octomap_->resolution : 0.0},
                              {"occupied_cells", cloud_ ? cloud_->width * cloud_->height : 0u}}},
                            {"matcher", matchSummary()},
                            {"files",
                             {{"octree", hull.empty() ? "" : hull + ".bt"},
                              {"mesh", hull.empty() ? "" : hull + ".ply"},
                              {"point_cloud", saveCloud()},
                              {"matches_image", saveMatchesImage()}}}};
  std::ofstream(config_.out_dir + "/summary.json") << summary.dump(2) << "\n";
  return summary;
}

}  // namespace sift_hull
