#include "ros_harness.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <thread>

#include "free_port.h"
#include "sift_hull/process.h"

namespace sift_hull {
namespace cli {
namespace {

/// Starts `command` with its stdout and stderr appended to `log_path`.
pid_t spawn(const std::vector<std::string>& command, const std::string& log_path) {
  const pid_t pid = startProgram(command, log_path, ProgramOutput::kBothAppendedToFile);
  if (pid < 0) throw std::runtime_error("cannot start " + command.front());
  return pid;
}

bool waitExit(pid_t pid, std::chrono::seconds limit) {
  const auto deadline = std::chrono::steady_clock::now() + limit;
  while (std::chrono::steady_clock::now() < deadline) {
    if (waitpid(pid, nullptr, WNOHANG) == pid) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return false;
}

void interrupt(pid_t pid) {
  kill(pid, SIGINT);
  if (!waitExit(pid, std::chrono::seconds(10))) {
    kill(pid, SIGKILL);
    waitpid(pid, nullptr, 0);
  }
}

bool accepts(int port) {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<uint16_t>(port));
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  const bool open = connect(fd, reinterpret_cast<sockaddr*>(&address), sizeof(address)) == 0;
  close(fd);
  return open;
}

/// Until `port` accepts connections, while `server` lives.
bool waitForPort(int port, pid_t server, std::chrono::seconds limit) {
  const auto deadline = std::chrono::steady_clock::now() + limit;
  while (std::chrono::steady_clock::now() < deadline) {
    if (accepts(port)) return true;
    if (waitpid(server, nullptr, WNOHANG) == server) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  return false;
}

std::string executableDirectory() {
  return std::filesystem::read_symlink("/proc/self/exe").parent_path().string();
}

}  // namespace

RosHarness::RosHarness() {
  const int port = freeTcpPort();
  const std::string uri = "http://localhost:" + std::to_string(port) + "/";
  setenv("ROS_MASTER_URI", uri.c_str(), 1);
  log_path_ = (std::filesystem::temp_directory_path() /
               ("sift_hull_ros_harness_" + std::to_string(getpid()) + ".log"))
                  .string();
  master_ = spawn({"rosmaster", "--core", "-p", std::to_string(port)}, log_path_);
  if (!waitForPort(port, master_, std::chrono::seconds(20))) {
    interrupt(master_);
    throw std::runtime_error("no ROS master at " + uri + " after 20 s");
  }
}

RosHarness::~RosHarness() {
  for (pid_t pid : nodes_) interrupt(pid);
  interrupt(master_);
}

pid_t RosHarness::startNode(const std::string& executable,
                            const std::vector<std::string>& arguments) {
  std::vector<std::string> command = {executableDirectory() + "/" + executable};
  command.insert(command.end(), arguments.begin(), arguments.end());
  nodes_.push_back(spawn(command, log_path_));
  return nodes_.back();
}

void RosHarness::stopNode(pid_t pid) {
  const auto found = std::find(nodes_.begin(), nodes_.end(), pid);
  if (found == nodes_.end()) return;
  nodes_.erase(found);
  interrupt(pid);
}

double residentMiB(pid_t pid) {
  std::ifstream status("/proc/" + std::to_string(pid) + "/status");
  std::string key;
  while (status >> key) {
    if (key == "VmRSS:") {
      double kib = 0.0;
      status >> kib;
      return kib / 1024.0;
    }
    status.ignore(1 << 12, '\n');
  }
  return 0.0;
}

}  // namespace cli
}  // namespace sift_hull
