// The two nodes as nodelets, for a nodelet manager shared with image_proc and friends: images then
// reach the matcher without a copy.
#include <nodelet/nodelet.h>

#include <chrono>
#include <condition_variable>
#include <exception>
#include <memory>
#include <mutex>
#include <pluginlib/class_list_macros.hpp>
#include <set>
#include <stdexcept>
#include <string>

#include "nodes/hull_node.h"
#include "nodes/matcher_node.h"

namespace sift_hull {
namespace {

/// Wall time a nodelet loaded again waits for its previous instance to be gone.
constexpr double kPreviousInstanceWait_s = 30.0;

/// The names of this library's nodelets alive in the manager. A nodelet unloaded while one of its
/// callbacks runs lives on until that callback returns (the manager's worker holds it), with its
/// services still advertised; an instance loaded under its name meanwhile would be refused them
/// ("already advertised") and run without. So an instance takes its name only once the previous
/// holder has released it, on destruction.
class LiveNames {
 public:
  static LiveNames& instance() {
    static LiveNames names;
    return names;
  }

  /// Waits up to `timeout_s` for `name` to be free and takes it; false when it stayed taken.
  bool take(const std::string& name, double timeout_s) {
    std::unique_lock<std::mutex> lock(mutex_);
    const auto free = [&] { return names_.count(name) == 0; };
    if (!released_.wait_for(lock, std::chrono::duration<double>(timeout_s), free)) return false;
    names_.insert(name);
    return true;
  }

  void release(const std::string& name) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      names_.erase(name);
    }
    released_.notify_all();
  }

 private:
  std::mutex mutex_;
  std::condition_variable released_;
  std::set<std::string> names_;
};

}  // namespace

/// Runs Node on the nodelet's node handles. A configuration error is logged as fatal, naming the
/// parameter, and thrown on to the manager, which then unloads the nodelet and answers the load
/// request with a failure (the `nodelet load` process exits with an error).
template <typename Node>
class WrapperNodelet : public nodelet::Nodelet {
 public:
  ~WrapperNodelet() override {
    node_.reset();  // its services, subscriptions and workers end here
    if (named_) LiveNames::instance().release(getName());
  }

 private:
  void onInit() override {
    if (!LiveNames::instance().take(getName(), kPreviousInstanceWait_s)) {
      const std::string why = "the previous instance of this nodelet is still running after " +
                              std::to_string(static_cast<int>(kPreviousInstanceWait_s)) + " s";
      NODELET_FATAL("%s: not loaded: %s", getName().c_str(), why.c_str());
      throw std::runtime_error(getName() + ": " + why);
    }
    named_ = true;
    try {
      node_ = std::make_unique<Node>(getNodeHandle(), getPrivateNodeHandle());
    } catch (const std::exception& e) {
      NODELET_FATAL("%s: not loaded: %s", getName().c_str(), e.what());
      throw;
    }
  }

  bool named_ = false;  ///< holds its name in LiveNames
  std::unique_ptr<Node> node_;
};

class HullNodelet : public WrapperNodelet<HullNode> {};
class MatcherNodelet : public WrapperNodelet<MatcherNode> {};

}  // namespace sift_hull

PLUGINLIB_EXPORT_CLASS(sift_hull::HullNodelet, nodelet::Nodelet)
PLUGINLIB_EXPORT_CLASS(sift_hull::MatcherNodelet, nodelet::Nodelet)
