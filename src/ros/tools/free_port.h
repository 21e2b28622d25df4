#pragma once

#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <stdexcept>

namespace sift_hull {

/// A TCP port on the loopback interface that nothing listens on now (the kernel's choice), for a
/// ROS master of its own: bench-nodes' harness (ros_harness.cpp) and test/ros/test_demo_launch.cpp.
inline int freeTcpPort() {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t length = sizeof(address);
  const bool found = fd >= 0 && bind(fd, reinterpret_cast<sockaddr*>(&address), length) == 0 &&
                     getsockname(fd, reinterpret_cast<sockaddr*>(&address), &length) == 0;
  if (fd >= 0) close(fd);
  if (!found) throw std::runtime_error("no free TCP port");
  return ntohs(address.sin_port);
}

}  // namespace sift_hull
