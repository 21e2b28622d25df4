#pragma once

#include <diagnostic_updater/diagnostic_updater.h>
#include <ros/ros.h>

#include <functional>
#include <string>

#include "lib/work_queue.h"

namespace sift_hull {

/// A node's one /diagnostics task, published every `period_s` seconds of wall time (the node
/// config's diagnostic_period, read from ~diagnostic_period like diagnostic_updater itself does):
/// diagnostic_updater waits on ROS time, which stops with a bag's clock.
class NodeDiagnostics {
 public:
  using Report = std::function<void(diagnostic_updater::DiagnosticStatusWrapper&)>;

  NodeDiagnostics(ros::NodeHandle nh, const ros::NodeHandle& private_nh, const std::string& task,
                  double period_s, Report report)
      : updater_(nh, private_nh, private_nh.getNamespace()) {
    updater_.setHardwareID("none");
    updater_.add(task, std::move(report));
    timer_ = nh.createWallTimer(ros::WallDuration(period_s),
                                [this](const ros::WallTimerEvent&) { updater_.force_update(); });
  }

 private:
  diagnostic_updater::Updater updater_;
  ros::WallTimer timer_;
};

/// A work queue's counts in a diagnostics task: OK while nothing was dropped, WARN once the input
/// has outrun the processing.
inline void reportQueue(const WorkCounts& counts, const std::string& items,
                        diagnostic_updater::DiagnosticStatusWrapper* status) {
  status->add(items + " received", counts.pushed);
  status->add(items + " processed", counts.done);
  status->add(items + " dropped", counts.dropped);
  status->add(items + " waiting", counts.waiting);
  if (counts.dropped > 0) {
    status->summaryf(diagnostic_msgs::DiagnosticStatus::WARN,
                     "%llu %s dropped: the input comes faster than they are processed",
                     static_cast<unsigned long long>(counts.dropped), items.c_str());
  } else {
    status->summary(diagnostic_msgs::DiagnosticStatus::OK, "keeping up");
  }
}

/// Queues `item`; when that dropped an older one, says so (throttled) with the running count.
template <typename Item>
void pushCounted(WorkQueue<Item>* queue, Item item, const std::string& what) {
  if (queue->push(std::move(item))) return;
  ROS_WARN_THROTTLE(5.0, "%s: %llu dropped so far (the input comes faster than it is processed)",
                    what.c_str(), static_cast<unsigned long long>(queue->counts().dropped));
}

}  // namespace sift_hull
