// Hostile input for hull_node and matcher_node (test/bad_inputs.test). Each bad message must
// (a) give a specific error from that node on /rosout, (b) leave the node running (the same
// process answers its XML-RPC getPid), and (c) not keep a good message sent after it from being
// processed (octomap_binary / correspondences). Floods must leave the node's resident memory
// flat. Every wait has a deadline.
//
// This file: matcher_node.

#include "bad_inputs.h"

namespace sift_hull {
namespace bad_inputs {
namespace {

// ---- matcher_node ----------------------------------------------------------------------------

struct MatcherData {
  RenderedView left, right;          // 320x240
  RenderedView big_left, big_right;  // 640x480, for the flood
};

const MatcherData& matcherData() {
  static const MatcherData data = [] {
    MatcherData d;
    SceneConfig config;
    config.width_px = 320;
    config.height_px = 240;
    d.left = renderSceneView(config, 0);
    d.right = renderSceneView(config, 1);
    config.width_px = 640;
    config.height_px = 480;
    d.big_left = renderSceneView(config, 0);
    d.big_right = renderSceneView(config, 1);
    return d;
  }();
  return data;
}

class MatcherBadInputTest : public NodeUnderTest {
 protected:
  void SetUp() override {
    const MatcherData& data = matcherData();
    left_ = &data.left;
    right_ = &data.right;
    // Queues long enough that a flood reaches the node rather than being dropped here.
    left_pub_ = nh_.advertise<sensor_msgs::Image>("hostile/left/image", kFlood + 10);
    right_pub_ = nh_.advertise<sensor_msgs::Image>("hostile/right/image", kFlood + 10);
    sub_ = nh_.subscribe("correspondences", kFlood + 10, &MatcherBadInputTest::onCorrespondences,
                         this);
    ASSERT_TRUE(waitFor([&] {
      return left_pub_.getNumSubscribers() > 0 && right_pub_.getNumSubscribers() > 0 &&
             sub_.getNumPublishers() > 0;
    })) << "the matcher node did not connect";
    ASSERT_NO_FATAL_FAILURE(findNode("/matcher"));
  }

  void onCorrespondences(const sift_hull::CorrespondencesConstPtr& message) {
    answered_[message->header.stamp] = message->matches.size();
  }

  void publishPair(const sensor_msgs::Image& left, const sensor_msgs::Image& right) {
    left_pub_.publish(left);
    right_pub_.publish(right);
  }

  /// A bad pair (`left` and `right` share `stamp`): refused with an error holding `needles`.
  void expectRefused(const sensor_msgs::Image& left, const sensor_msgs::Image& right,
                     const std::vector<std::string>& needles) {
    const size_t since = rosout().mark();
    publishPair(left, right);
    bad_.push_back(left.header.stamp);
    EXPECT_TRUE(loggedError("/matcher", needles, since));
  }

  /// A good pair is matched (at least 50 matches) and the node is the same process.
  void expectGoodPairMatched() {
    const ros::Time stamp = freshStamp();
    publishPair(imageMessage(left_->image, stamp, "left"),
                imageMessage(right_->image, stamp, "right"));
    ASSERT_TRUE(waitFor([&] { return answered_.count(stamp) > 0; }))
        << "a good pair after bad input was not matched; the matcher logged:\n"
        << rosout().linesOf("/matcher", 0);
    EXPECT_GE(answered_[stamp], 50u);
    expectAlive();
  }

  /// None of the bad pairs was answered, however late.
  void expectNoBadPairAnswered() {
    ros::WallDuration(0.3).sleep();
    ros::spinOnce();
    for (const ros::Time& stamp : bad_) EXPECT_EQ(answered_.count(stamp), 0u) << stamp;
  }

  const RenderedView* left_ = nullptr;
  const RenderedView* right_ = nullptr;
  ros::Publisher left_pub_, right_pub_;
  ros::Subscriber sub_;
  std::map<ros::Time, size_t> answered_;
  std::vector<ros::Time> bad_;
};

// 1. The image whose height x step wraps 32 bits (it crashed the node).
TEST_F(MatcherBadInputTest, WrapStepImageIsRefused) {
  const ros::Time stamp = freshStamp();
  expectRefused(wrapStepImage(stamp, "left"), imageMessage(right_->image, stamp, "right"),
                {"does not hold", std::to_string(kWrapStep)});
  expectAlive();
  expectGoodPairMatched();
  expectNoBadPairAnswered();
}

// 2. Encodings that are not 8-bit colour or mono, an empty image, data shorter than step x height.
TEST_F(MatcherBadInputTest, WrongEncodingsEmptyAndTruncatedImagesAreRefused) {
  const struct {
    const char* encoding;
    uint32_t bytes_per_pixel;
  } encodings[] = {{"16UC1", 2}, {"32FC1", 4}, {"bogus", 1}};
  for (const auto& bad : encodings) {
    const ros::Time stamp = freshStamp();
    sensor_msgs::Image image = imageMessage(left_->image, stamp, "left");
    image.encoding = bad.encoding;
    image.step = image.width * bad.bytes_per_pixel;
    image.data.assign(static_cast<size_t>(image.step) * image.height, 128);
    expectRefused(image, imageMessage(right_->image, stamp, "right"),
                  {"encoding '" + std::string(bad.encoding) + "'"});
    expectAlive();
  }
  {
    const ros::Time stamp = freshStamp();
    sensor_msgs::Image empty = imageMessage(left_->image, stamp, "left");
    empty.width = empty.height = empty.step = 0;
    empty.data.clear();
    expectRefused(empty, imageMessage(right_->image, stamp, "right"), {"the image is empty (0x0)"});
    expectAlive();
  }
  {
    const ros::Time stamp = freshStamp();
    sensor_msgs::Image truncated = imageMessage(right_->image, stamp, "right");
    truncated.data.resize(static_cast<size_t>(truncated.step) * (truncated.height - 1));
    expectRefused(imageMessage(left_->image, stamp, "left"), truncated,
                  {"does not hold", std::to_string(truncated.data.size()) + " bytes"});
    expectAlive();
  }
  expectGoodPairMatched();
  expectNoBadPairAnswered();
}

// 3. A pair over ~max_image_pixels (default 25 megapixels): refused on arrival from the headers.
TEST_F(MatcherBadInputTest, ImagesOverMaxImagePixelsAreRefused) {
  const ros::Time stamp = freshStamp();
  sensor_msgs::Image big;
  big.header.stamp = stamp;
  big.header.frame_id = "left";
  big.encoding = "mono8";
  big.width = 6000;
  big.height = 5000;
  big.step = big.width;
  big.data.assign(static_cast<size_t>(big.step) * big.height, 0);
  big.data[12345] = 255;
  sensor_msgs::Image big_right = big;
  big_right.header.frame_id = "right";
  expectRefused(big, big_right, {"max_image_pixels", "6000x5000"});
  expectAlive();
  expectGoodPairMatched();
  expectNoBadPairAnswered();
}

// 4. 200 pairs of 640x480 as fast as they go: bounded queues keep the memory flat.
TEST_F(MatcherBadInputTest, FloodOfPairsKeepsTheNodeAliveAndItsMemoryFlat) {
  ASSERT_NO_FATAL_FAILURE(expectGoodPairMatched());  // warm: the first allocations are made
  const long before = rss();
  const MatcherData& data = matcherData();
  const sensor_msgs::Image left = imageMessage(data.big_left.image, {}, "left");
  const sensor_msgs::Image right = imageMessage(data.big_right.image, {}, "right");
  for (int i = 0; i < kFlood; ++i) {
    sensor_msgs::Image l = left, r = right;
    l.header.stamp = r.header.stamp = freshStamp();
    publishPair(l, r);
  }
  ros::spinOnce();
  expectGoodPairMatched();
  const long after = rss();
  EXPECT_LT(after - before, kMaxRssGrowthKiB)
      << "VmRSS of the matcher grew from " << before << " KiB to " << after << " KiB";
  std::cout << "matcher VmRSS before the flood " << before << " KiB, after " << after << " KiB, "
            << answered_.size() << " pairs answered in all\n";
}

// 5. Exact sync fed duplicate stamps and stamps back in time.
TEST_F(MatcherBadInputTest, DuplicateAndBackwardStampsAreSurvived) {
  const ros::Time t = freshStamp();
  const sensor_msgs::Image left = imageMessage(left_->image, t, "left");
  const sensor_msgs::Image right = imageMessage(right_->image, t, "right");
  publishPair(left, right);
  ASSERT_TRUE(waitFor([&] { return answered_.count(t) > 0; })) << "the first pair was not matched";
  publishPair(left, right);  // the same stamps again
  publishPair(left, right);
  for (double back_s : {1.0, 2.0, 0.5}) {  // back in time
    sensor_msgs::Image l = left, r = right;
    l.header.stamp = r.header.stamp = t - ros::Duration(back_s);
    publishPair(l, r);
  }
  {
    // One slot filled twice on the left, then once on the right; a right image twice alone.
    sensor_msgs::Image l = left, r = right;
    l.header.stamp = r.header.stamp = t - ros::Duration(3.0);
    left_pub_.publish(l);
    left_pub_.publish(l);
    right_pub_.publish(r);
    r.header.stamp = t - ros::Duration(4.0);
    right_pub_.publish(r);
    right_pub_.publish(r);
  }
  ros::WallDuration(1.0).sleep();
  expectAlive();
  expectGoodPairMatched();
}

}  // namespace
}  // namespace bad_inputs
}  // namespace sift_hull
