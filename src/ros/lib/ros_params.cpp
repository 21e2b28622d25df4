#include "lib/ros_params.h"

#include <stdexcept>
#include <string>
#include <vector>

namespace sift_hull {
namespace ros_params {
namespace {

thread_local ReadLog* active_log = nullptr;

/// The parameter's value, when it is set, as the setting's type; throws std::invalid_argument
/// naming it when it is set with another type.
template <typename T>
bool get(const ros::NodeHandle& private_nh, const SettingInfo& info, T* value) {
  if (!private_nh.getParam(info.name, *value)) {
    throw std::invalid_argument("~" + info.name + " is set, but not as a " +
                                settingTypeName(info.type));
  }
  return true;
}

/// roscpp would truncate 2.5 to 2 for an integer; here that is a wrong type too.
int getInteger(const ros::NodeHandle& private_nh, const SettingInfo& info) {
  XmlRpc::XmlRpcValue raw;
  private_nh.getParam(info.name, raw);
  if (raw.getType() != XmlRpc::XmlRpcValue::TypeInt) {
    throw std::invalid_argument("~" + info.name + " is set, but not as an integer");
  }
  return static_cast<int>(raw);
}

/// The set parameter of `info`, as its setting's value type.
SettingValue paramValue(const ros::NodeHandle& private_nh, const SettingInfo& info) {
  switch (info.type) {
    case SettingType::kBool: {
      bool value = false;
      get(private_nh, info, &value);
      return value;
    }
    case SettingType::kInt:
      return getInteger(private_nh, info);
    case SettingType::kSize: {
      const int value = getInteger(private_nh, info);
      if (value < 0) throw std::invalid_argument("~" + info.name + " must be >= 0");
      return static_cast<size_t>(value);
    }
    case SettingType::kDouble: {
      double value = 0.0;
      get(private_nh, info, &value);
      return value;
    }
    case SettingType::kString: {
      std::string value;
      get(private_nh, info, &value);
      return value;
    }
    case SettingType::kStringList: {
      std::vector<std::string> value;
      get(private_nh, info, &value);
      return value;
    }
    case SettingType::kNumberList: {
      std::vector<double> value;
      get(private_nh, info, &value);
      return value;
    }
  }
  throw std::logic_error("paramValue: unknown setting type");
}

/// ~world_frame, or octomap_server's ~frame_id for it; both set and different: an error.
void readFrameId(const ros::NodeHandle& private_nh, HullNodeConfig* config) {
  std::string frame_id;
  if (!private_nh.getParam("frame_id", frame_id)) return;
  if (private_nh.hasParam("world_frame") && frame_id != config->world_frame) {
    throw std::invalid_argument("~frame_id ('" + frame_id + "', octomap_server's map frame) and " +
                                "~world_frame ('" + config->world_frame +
                                "') differ: set ~world_frame only");
  }
  config->world_frame = frame_id;
}

/// tf2's rule for a frame id: named, and without the leading '/' tf1 allowed (tf2 refuses every
/// lookup with one).
void checkFrameId(const std::string& name, const std::string& frame) {
  if (frame.empty()) throw std::invalid_argument("~" + name + " must name a frame, not be empty");
  if (frame[0] == '/') {
    throw std::invalid_argument("~" + name + " '" + frame +
                                "' starts with '/', which tf2 refuses: write '" +
                                frame.substr(frame.find_first_not_of('/') == std::string::npos
                                                 ? frame.size()
                                                 : frame.find_first_not_of('/')) +
                                "'");
  }
}

}  // namespace

template <typename Config>
void readSettings(const ros::NodeHandle& private_nh, const SettingTable<Config>& table,
                  Config* config) {
  for (const Setting<Config>& setting : table.settings()) {
    if (active_log != nullptr) active_log->names.insert(setting.info.name);
    if (!private_nh.hasParam(setting.info.name)) continue;
    const SettingValue value = paramValue(private_nh, setting.info);
    try {
      checkSetting(setting.info, value);
      setting.set(config, value);
    } catch (const std::invalid_argument& error) {
      throw std::invalid_argument("~" + std::string(error.what()));
    }
  }
}

template void readSettings(const ros::NodeHandle&, const SettingTable<HullNodeConfig>&,
                           HullNodeConfig*);
template void readSettings(const ros::NodeHandle&, const SettingTable<HullStreamConfig>&,
                           HullStreamConfig*);
template void readSettings(const ros::NodeHandle&, const SettingTable<MatcherSettings>&,
                           MatcherSettings*);
template void readSettings(const ros::NodeHandle&, const SettingTable<ResultSaverConfig>&,
                           ResultSaverConfig*);

HullNodeConfig readHullNodeConfig(const ros::NodeHandle& private_nh) {
  HullNodeConfig config;
  readSettings(private_nh, settingsOf<HullNodeConfig>(), &config);
  readFrameId(private_nh, &config);
  checkFrameId("world_frame", config.world_frame);
  // A threshold given asks for the threshold recipe, unless a method is named too.
  if (private_nh.hasParam("threshold") && !private_nh.hasParam("silhouette_method")) {
    config.recipe.silhouette_method = "threshold";
  }
  return config;
}

HullStreamConfig readHullStreamConfig(const ros::NodeHandle& private_nh) {
  if (private_nh.hasParam("resolution")) {  // octomap_server's voxel edge
    throw std::invalid_argument(
        "~resolution (octomap_server's voxel edge) is not a hull_node parameter: set "
        "~resolution_m (metres, the same meaning) or ~max_depth");
  }
  HullStreamConfig config;
  readSettings(private_nh, settingsOf<HullStreamConfig>(), &config);
  validate(config);
  return config;
}

MatcherSettings readMatcherSettings(const ros::NodeHandle& private_nh) {
  MatcherSettings settings;
  readSettings(private_nh, settingsOf<MatcherSettings>(), &settings);
  if (settings.node.frame_to_frame && settings.node.calibrated) {
    checkFrameId("world_frame", settings.node.world_frame);
  }
  return settings;
}

ResultSaverConfig readResultSaverConfig(const ros::NodeHandle& private_nh) {
  ResultSaverConfig config;
  readSettings(private_nh, settingsOf<ResultSaverConfig>(), &config);
  if (config.bag.empty() || config.out_dir.empty()) {
    throw std::invalid_argument("~bag and ~out_dir are required");
  }
  return config;
}

ReadLog::ReadLog() : outer_(active_log) { active_log = this; }

ReadLog::~ReadLog() { active_log = outer_; }

}  // namespace ros_params
}  // namespace sift_hull
