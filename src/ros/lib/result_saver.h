#pragma once

#include <diagnostic_msgs/DiagnosticArray.h>
#include <ros/ros.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud2.h>

#include <nlohmann/json.hpp>
#include <string>

#include "sift_hull/Correspondences.h"
#include "sift_hull/Octomap.h"
#include "sift_hull/settings.h"

namespace sift_hull {

/// What save_results waits for and where it writes.
struct ResultSaverConfig {
  std::string bag;      ///< the bag being played (written by `sift_hull bag`)
  std::string out_dir;  ///< created if missing
  std::string hull_save_service = "hull/save";
  /// Give up waiting this long after start (wall time) and save what there is.
  double timeout_s = 120.0;
  /// Once everything is saved, end the roslaunch that started the node (as Ctrl-C does).
  bool end_launch = false;
};

/// Its settings (sift_hull/settings.h): save_results' private parameters.
template <>
const SettingTable<ResultSaverConfig>& settingsOf<ResultSaverConfig>();

/// The last view and the last stereo pair in a bag of `sift_hull bag`, by header stamp.
struct BagEnd {
  int views = 0, pairs = 0;
  ros::Time last_view, last_pair;
};

/// Reads the stamps of the bag's silhouettes and left images. Throws rosbag::BagException.
BagEnd readBagEnd(const std::string& bag_path);

/// Listens to the hull and matcher nodes' outputs until they carry the bag's last stamps, then
/// saves them: hull.bt and hull.ply (through the hull node's ~save), occupied_cells.pcd,
/// matches.png and summary.json.
class ResultSaver {
 public:
  ResultSaver(ros::NodeHandle nh, ResultSaverConfig config, BagEnd bag_end);
  /// Whether the latest outputs carry the stamps of the bag's last view and last pair.
  bool complete() const;
  /// Writes the files; returns the summary (also written as summary.json).
  nlohmann::json save();

 private:
  void onOctomap(const sift_hull::OctomapConstPtr& message);
  void onCloud(const sensor_msgs::PointCloud2ConstPtr& message);
  void onCorrespondences(const sift_hull::CorrespondencesConstPtr& message);
  void onMatchesImage(const sensor_msgs::ImageConstPtr& message);
  void onDiagnostics(const diagnostic_msgs::DiagnosticArrayConstPtr& array);
  std::string saveHull() const;
  std::string saveCloud() const;
  std::string saveMatchesImage() const;
  nlohmann::json matchSummary() const;

  ros::NodeHandle nh_;
  ResultSaverConfig config_;
  BagEnd bag_end_;
  int hull_updates_ = 0, pairs_matched_ = 0;
  sift_hull::OctomapConstPtr octomap_;
  sensor_msgs::PointCloud2ConstPtr cloud_;
  sift_hull::CorrespondencesConstPtr correspondences_;
  sensor_msgs::ImageConstPtr matches_image_;
  double hull_last_view_s_ = -1.0;  ///< the stamp of the last view the hull node processed
  ros::Subscriber octomap_sub_, cloud_sub_, correspondences_sub_, matches_image_sub_,
      diagnostics_sub_;
};

}  // namespace sift_hull
