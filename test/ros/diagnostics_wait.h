#pragma once

// Waiting for a node's /diagnostics task to warn, in the rostests.

#include <diagnostic_msgs/DiagnosticArray.h>
#include <ros/ros.h>

#include <cmath>
#include <cstdlib>
#include <functional>
#include <mutex>
#include <string>

namespace sift_hull {
namespace test {

/// Calls `poke` (which publishes what should make the node warn) every 0.25 s until the
/// /diagnostics status whose name holds `task` is WARN with a message holding `text`, at most
/// `deadline_s` of wall time; returns that message, or empty after the deadline.
inline std::string warningOf(ros::NodeHandle& nh, const std::string& task, const std::string& text,
                             const std::function<void()>& poke, double deadline_s = 20.0) {
  std::mutex mutex;
  std::string warning;
  ros::Subscriber diagnostics = nh.subscribe<diagnostic_msgs::DiagnosticArray>(
      "/diagnostics", 20, [&](const diagnostic_msgs::DiagnosticArrayConstPtr& array) {
        std::lock_guard<std::mutex> lock(mutex);
        for (const diagnostic_msgs::DiagnosticStatus& status : array->status) {
          if (status.name.find(task) == std::string::npos) continue;
          warning = status.level == diagnostic_msgs::DiagnosticStatus::WARN ? status.message : "";
        }
      });
  const ros::WallTime start = ros::WallTime::now();
  while ((ros::WallTime::now() - start).toSec() < deadline_s) {
    poke();
    ros::WallDuration(0.25).sleep();
    ros::spinOnce();
    std::lock_guard<std::mutex> lock(mutex);
    if (warning.find(text) != std::string::npos) return warning;
  }
  return "";
}

/// The text of `key` in the /diagnostics status whose name holds `task`, once `accept` takes it,
/// at most `deadline_s` of wall time; empty after the deadline.
inline std::string diagnosticText(ros::NodeHandle& nh, const std::string& task,
                                  const std::string& key,
                                  const std::function<bool(const std::string&)>& accept,
                                  double deadline_s = 20.0) {
  std::mutex mutex;
  std::string text;
  bool found = false;
  ros::Subscriber diagnostics = nh.subscribe<diagnostic_msgs::DiagnosticArray>(
      "/diagnostics", 20, [&](const diagnostic_msgs::DiagnosticArrayConstPtr& array) {
        std::lock_guard<std::mutex> lock(mutex);
        for (const diagnostic_msgs::DiagnosticStatus& status : array->status) {
          if (status.name.find(task) == std::string::npos) continue;
          for (const diagnostic_msgs::KeyValue& pair : status.values) {
            if (pair.key == key) text = pair.value, found = true;
          }
        }
      });
  const ros::WallTime start = ros::WallTime::now();
  while ((ros::WallTime::now() - start).toSec() < deadline_s) {
    ros::WallDuration(0.1).sleep();
    ros::spinOnce();
    std::lock_guard<std::mutex> lock(mutex);
    if (found && accept(text)) return text;
  }
  return "";
}

/// The value of `key` in the /diagnostics status whose name holds `task`, once `accept` takes it,
/// at most `deadline_s` of wall time; NaN after the deadline.
inline double diagnosticValue(ros::NodeHandle& nh, const std::string& task, const std::string& key,
                              const std::function<bool(double)>& accept, double deadline_s = 20.0) {
  std::mutex mutex;
  double value = std::nan("");
  ros::Subscriber diagnostics = nh.subscribe<diagnostic_msgs::DiagnosticArray>(
      "/diagnostics", 20, [&](const diagnostic_msgs::DiagnosticArrayConstPtr& array) {
        std::lock_guard<std::mutex> lock(mutex);
        for (const diagnostic_msgs::DiagnosticStatus& status : array->status) {
          if (status.name.find(task) == std::string::npos) continue;
          for (const diagnostic_msgs::KeyValue& pair : status.values) {
            if (pair.key == key) value = std::atof(pair.value.c_str());
          }
        }
      });
  const ros::WallTime start = ros::WallTime::now();
  while ((ros::WallTime::now() - start).toSec() < deadline_s) {
    ros::WallDuration(0.1).sleep();
    ros::spinOnce();
    std::lock_guard<std::mutex> lock(mutex);
    if (!std::isnan(value) && accept(value)) return value;
  }
  return std::nan("");
}

}  // namespace test
}  // namespace sift_hull
