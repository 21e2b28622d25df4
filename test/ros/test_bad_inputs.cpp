// Hostile input for hull_node and matcher_node (test/bad_inputs.test). Each bad message must
// (a) give a specific error from that node on /rosout, (b) leave the node running (the same
// process answers its XML-RPC getPid), and (c) not keep a good message sent after it from being
// processed (octomap_binary / correspondences). Floods must leave the node's resident memory
// flat. Every wait has a deadline.
//
// The main of the test: the cases are in test_bad_inputs_matcher.cpp and test_bad_inputs_hull.cpp.

#include <gtest/gtest.h>
#include <ros/ros.h>

#include <iostream>

#include "bad_inputs.h"

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_bad_inputs");
  ros::NodeHandle nh;  // keeps the node alive through the tests
  sift_hull::bad_inputs::rosout().start(nh);
  // Connected to every publisher of /rosout: this process, the hull and the matcher node (the
  // fixtures then wait for each node's topics).
  if (!sift_hull::test::waitFor(
          [] { return sift_hull::bad_inputs::rosout().subscriber().getNumPublishers() >= 3; })) {
    std::cerr << "warning: /rosout has "
              << sift_hull::bad_inputs::rosout().subscriber().getNumPublishers()
              << " publishers connected, expected 3 (this test, hull, matcher)\n";
  }
  return RUN_ALL_TESTS();
}
