#pragma once

// The private parameters of the nodes, read from the config structs' settings tables
// (sift_hull/settings.h): a parameter is named as its setting, and every fallback is the struct's
// own default. A parameter set with the wrong type (a string where a list is expected, 2.5 for an
// integer) or outside its range is an error (std::invalid_argument naming it), not a silent
// default. octomap_server's names for the hull node's settings are understood too: ~frame_id as
// ~world_frame, and ~resolution refused with the setting to use instead (~resolution_m).

#include <ros/node_handle.h>

#include <set>
#include <string>

#include "lib/result_saver.h"
#include "nodes/hull_node_config.h"
#include "nodes/matcher_node_config.h"
#include "sift_hull/settings.h"

namespace sift_hull {
namespace ros_params {

/// Sets each setting of `table` whose private parameter is set, on `config`; the others keep
/// their value. Throws std::invalid_argument for a parameter of the wrong type or out of range.
template <typename Config>
void readSettings(const ros::NodeHandle& private_nh, const SettingTable<Config>& table,
                  Config* config);

/// hull_node's settings (HullNodeConfig's table), octomap_server's ~frame_id read as
/// ~world_frame (an error when both are set and differ). A ~threshold given without
/// ~silhouette_method asks for the threshold method.
HullNodeConfig readHullNodeConfig(const ros::NodeHandle& private_nh);

/// The hull's settings (HullStreamConfig's table); octomap_server's ~resolution is refused
/// (std::invalid_argument naming ~resolution_m).
HullStreamConfig readHullStreamConfig(const ros::NodeHandle& private_nh);

/// matcher_node's settings (MatcherSettings' table).
MatcherSettings readMatcherSettings(const ros::NodeHandle& private_nh);

/// ~bag, ~out_dir (both required: throws std::invalid_argument without them),
/// ~hull_save_service, ~timeout_s.
ResultSaverConfig readResultSaverConfig(const ros::NodeHandle& private_nh);

/// While one is alive, records the parameter names the readers called on its thread look up. For
/// tests: a parameter file must state every name read.
class ReadLog {
 public:
  ReadLog();
  ~ReadLog();
  ReadLog(const ReadLog&) = delete;
  ReadLog& operator=(const ReadLog&) = delete;

  std::set<std::string> names;

 private:
  ReadLog* outer_;
};

}  // namespace ros_params
}  // namespace sift_hull
