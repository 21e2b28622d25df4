#pragma once

#include <sys/types.h>

#include <string>
#include <vector>

namespace sift_hull {
namespace cli {

/// A ROS master of its own on a free port, and node processes started against it, for
/// benchmarks that measure the nodes as users run them (separate processes, messages serialised).
/// Everything started is interrupted, then killed, when the harness goes.
class RosHarness {
 public:
  /// Starts `rosmaster --core` and points this process (ROS_MASTER_URI) at it; ros::init may
  /// follow. Throws std::runtime_error when the master does not come up in 20 s.
  RosHarness();
  ~RosHarness();
  RosHarness(const RosHarness&) = delete;
  RosHarness& operator=(const RosHarness&) = delete;

  /// Starts one of the package's executables (next to this program) with ROS arguments such as
  /// "__name:=matcher" and "_workers:=2"; returns its pid.
  pid_t startNode(const std::string& executable, const std::vector<std::string>& arguments);
  /// Interrupts a node started here and waits for it (killed after 10 s).
  void stopNode(pid_t pid);
  /// Where the master and the nodes write their output.
  const std::string& logPath() const { return log_path_; }

 private:
  std::string log_path_;
  pid_t master_ = -1;
  std::vector<pid_t> nodes_;
};

/// A process's resident memory now, in MiB (/proc/PID/status VmRSS); 0 when it is gone.
double residentMiB(pid_t pid);

}  // namespace cli
}  // namespace sift_hull
