// The two nodes as nodelets, for a nodelet manager shared with image_proc and friends: images then
// reach the matcher without a copy.
#include <nodelet/nodelet.h>

#include <exception>
#include <memory>
#include <pluginlib/class_list_macros.hpp>

#include "nodes/hull_node.h"
#include "nodes/matcher_node.h"

namespace sift_hull {

/// Runs Node on the nodelet's node handles. A configuration error is logged as fatal and leaves
/// the nodelet idle rather than taking the whole manager down.
template <typename Node>
class WrapperNodelet : public nodelet::Nodelet {
 private:
  void onInit() override {
    try {
      node_ = std::make_unique<Node>(getNodeHandle(), getPrivateNodeHandle());
    } catch (const std::exception& e) {
      NODELET_FATAL("%s", e.what());
    }
  }

  std::unique_ptr<Node> node_;
};

class HullNodelet : public WrapperNodelet<HullNode> {};
class MatcherNodelet : public WrapperNodelet<MatcherNode> {};

}  // namespace sift_hull

PLUGINLIB_EXPORT_CLASS(sift_hull::HullNodelet, nodelet::Nodelet)
PLUGINLIB_EXPORT_CLASS(sift_hull::MatcherNodelet, nodelet::Nodelet)
