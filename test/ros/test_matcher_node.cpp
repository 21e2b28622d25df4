// The matcher node wired up: a synthetic stereo pair in, correspondences out with the input stamps
// and a precision against the scene's ground truth; bad pairs answered with an error while later
// good pairs still count. Every wait has a deadline.

#include <cmath>

#include "matcher_node_fixture.h"

namespace sift_hull {
namespace {

TEST_F(MatcherNodeTest, MatchesAPairWithTheInputStampsAndGoodPrecision) {
  const ros::Time stamp = publishPair(left_.image, right_.image);
  ASSERT_TRUE(answeredAtLeast(stamp)) << "no correspondences for the pair";
  EXPECT_EQ(last_->header.stamp, stamp);
  EXPECT_EQ(last_->header.frame_id, "left");
  EXPECT_EQ(last_->right_header.frame_id, "right");
  ASSERT_EQ(last_->filters, (std::vector<std::string>{"gsc", "magsac"}));
  ASSERT_GE(last_->matches.size(), 50u);

  const PutativeMatches putatives = putativesOf(*last_, left_.image.size());
  const std::vector<MatchTruth> truth = judgeBySceneDepth(
      putatives, {left_.view.camera, left_.depth}, {right_.view.camera, right_.depth});
  size_t kept = 0, kept_correct = 0;
  for (size_t m = 0; m < truth.size(); ++m) {
    if (!(last_->matches[m].kept_by & 1u) || truth[m] == MatchTruth::kUnknown) continue;
    ++kept;
    kept_correct += truth[m] == MatchTruth::kCorrect;
  }
  ASSERT_GT(kept, 20u);
  EXPECT_GE(static_cast<double>(kept_correct) / kept, 0.9);  // gsc's precision on this pair
}

TEST_F(MatcherNodeTest, RefusesBadPairsAndCarriesOn) {
  const auto any = [](double) { return true; };
  const double left_unpaired = test::diagnosticValue(nh_, "matcher", "left/image unpaired", any);
  const double right_unpaired = test::diagnosticValue(nh_, "matcher", "right/image unpaired", any);
  ASSERT_FALSE(std::isnan(left_unpaired) || std::isnan(right_unpaired)) << "no unpaired counts";
  const cv::Mat black = cv::Mat::zeros(left_.image.size(), CV_8UC3);
  std::vector<ros::Time> bad;
  bad.push_back(publishPair(black, black));             // fewer than two keypoints
  bad.push_back(publishPair(left_.image, cv::Mat()));   // a left image without its right partner
  bad.push_back(publishPair(cv::Mat(), right_.image));  // a right image without its left partner
  sensor_msgs::Image empty = bgrImage(left_.image, ros::Time::now(), "left");
  empty.width = empty.height = empty.step = 0;  // an empty image
  empty.data.clear();
  left_pub_.publish(empty);
  right_pub_.publish(bgrImage(right_.image, empty.header.stamp, "right"));
  bad.push_back(empty.header.stamp);
  sensor_msgs::Image depth = bgrImage(right_.image, ros::Time::now(), "right");
  depth.encoding = "16UC1";  // not an 8-bit image
  depth.step = right_.image.cols * 2;
  depth.data.resize(depth.step * depth.height);
  left_pub_.publish(bgrImage(left_.image, depth.header.stamp, "left"));
  right_pub_.publish(depth);
  bad.push_back(depth.header.stamp);
  const ros::Time stamp = publishPair(left_.image, right_.image);
  ASSERT_TRUE(answeredAtLeast(stamp)) << "a good pair after bad ones was not matched";
  ros::WallDuration(0.5).sleep();  // a bad pair that was matched after all would be in by now
  ros::spinOnce();
  expectNoneAnswered(bad);
  EXPECT_EQ(answered_.size(), 1u);
  // The image without its partner on each side is counted, once.
  EXPECT_FALSE(std::isnan(test::diagnosticValue(nh_, "matcher", "left/image unpaired",
                                                [&](double v) { return v == left_unpaired + 1; })));
  EXPECT_FALSE(std::isnan(test::diagnosticValue(
      nh_, "matcher", "right/image unpaired", [&](double v) { return v == right_unpaired + 1; })));
}

TEST_F(MatcherNodeTest, WarnsWhenImagesArriveButDoNotPair) {
  ASSERT_TRUE(answeredAtLeast(publishPair(left_.image, right_.image)));
  // Stereo stamps 5 ms apart under exact sync: nothing pairs.
  const std::string warning = test::warningOf(nh_, "matcher", "have not paired", [&] {
    const ros::Time stamp = ros::Time::now();
    left_pub_.publish(bgrImage(left_.image, stamp, "left"));
    right_pub_.publish(bgrImage(right_.image, stamp + ros::Duration(0.005), "right"));
  });
  ASSERT_FALSE(warning.empty()) << "no WARN on /diagnostics within 20 s";
  EXPECT_NE(warning.find("left/image ("), std::string::npos) << warning;
  EXPECT_NE(warning.find("right/image ("), std::string::npos) << warning;
  EXPECT_NE(warning.find("~approximate_sync"), std::string::npos) << warning;
}

TEST_F(MatcherNodeTest, ThresholdsChangeAtRunTime) {
  const auto keptByGsc = [&] {
    size_t kept = 0;
    for (const sift_hull::Correspondence& c : last_->matches) kept += c.kept_by & 1u;
    return kept;
  };
  ros::Time stamp = publishPair(left_.image, right_.image);
  ASSERT_TRUE(answeredAtLeast(stamp));
  const size_t kept_by_default = keptByGsc();
  ASSERT_GT(kept_by_default, 20u);
  dynamic_reconfigure::Reconfigure change;
  dynamic_reconfigure::DoubleParameter threshold;
  threshold.name = "gsc_max_histogram_distance";
  threshold.value = 0.1;  // the strictest the setting takes (its default: 0.2)
  change.request.config.doubles.push_back(threshold);
  ASSERT_TRUE(ros::service::waitForService("/matcher/set_parameters", ros::Duration(kDeadline_s)));
  ASSERT_TRUE(ros::service::call("/matcher/set_parameters", change));
  stamp = publishPair(left_.image, right_.image);
  ASSERT_TRUE(answeredAtLeast(stamp));
  EXPECT_LT(keptByGsc(), kept_by_default);
  EXPECT_NE(last_->filter_settings.find("\"gsc_max_histogram_distance\":0.1"), std::string::npos)
      << last_->filter_settings;
}

/// `name`'s value in a published reconfigure config (NaN when absent).
double publishedValue(const dynamic_reconfigure::Config& config, const std::string& name) {
  for (const auto& p : config.doubles) {
    if (p.name == name) return p.value;
  }
  return std::numeric_limits<double>::quiet_NaN();
}

TEST_F(MatcherNodeTest, ARefusedValueLeavesTheServerOnTheLastAcceptedOne) {
  std::vector<dynamic_reconfigure::Config> published;  // ~parameter_updates, latched
  ros::Subscriber updates = nh_.subscribe<dynamic_reconfigure::Config>(
      "/matcher/parameter_updates", 5,
      [&](const dynamic_reconfigure::ConfigConstPtr& m) { published.push_back(*m); });
  ASSERT_TRUE(waitFor([&] { return !published.empty(); })) << "no ~parameter_updates";
  sift_hull::MatcherConfig config = sift_hull::MatcherConfig::__getDefault__();
  ASSERT_TRUE(config.__fromMessage__(published.back()));
  dynamic_reconfigure::Client<sift_hull::MatcherConfig> client("/matcher");
  config.max_descriptor_distance = 400.0;
  ASSERT_TRUE(client.setConfiguration(config));
  ASSERT_TRUE(waitFor([&] {
    return !published.empty() &&
           publishedValue(published.back(), "max_descriptor_distance") == 400.0;
  }));
  const size_t accepted = published.size();
  config.max_descriptor_distance = std::numeric_limits<double>::quiet_NaN();
  ASSERT_TRUE(client.setConfiguration(config));  // answered with the config in force
  EXPECT_EQ(config.max_descriptor_distance, 400.0);
  ASSERT_TRUE(waitFor([&] { return published.size() > accepted; })) << "no update for the refusal";
  EXPECT_EQ(publishedValue(published.back(), "max_descriptor_distance"), 400.0);
  const ros::Time stamp = publishPair(left_.image, right_.image);
  ASSERT_TRUE(answeredAtLeast(stamp)) << "no correspondences after the refused value";
  EXPECT_GE(last_->matches.size(), 20u);
  EXPECT_NE(last_->filter_settings.find("\"max_descriptor_distance\":400.0"), std::string::npos)
      << last_->filter_settings;
}

/// Compressed images (PNG and JPEG) on left/image/compressed and right/image/compressed, with
/// ~image_transport: compressed: decoded by the node when no image_transport plugin does it.
class CompressedMatcherTest : public MatcherNodeTest {
 protected:
  bool inputsConnected() const override {
    return left_compressed_pub_.getNumSubscribers() > 0 &&
           right_compressed_pub_.getNumSubscribers() > 0;
  }
  void advertise() override {
    left_compressed_pub_ = nh_.advertise<sensor_msgs::CompressedImage>("left/image/compressed", 5);
    right_compressed_pub_ =
        nh_.advertise<sensor_msgs::CompressedImage>("right/image/compressed", 5);
  }
  static sensor_msgs::CompressedImage compressed(const cv::Mat& image, const ros::Time& stamp,
                                                 const std::string& frame,
                                                 const std::string& format) {
    sensor_msgs::CompressedImage message;
    message.header.stamp = stamp;
    message.header.frame_id = frame;
    message.format = "bgr8; " + format + " compressed bgr8";
    cv::imencode("." + format, image, message.data);
    return message;
  }

  ros::Publisher left_compressed_pub_, right_compressed_pub_;
};

TEST_F(CompressedMatcherTest, DecodesCompressedPairsAndRefusesUndecodableOnes) {
  sensor_msgs::CompressedImage garbage = compressed(left_.image, ros::Time::now(), "left", "png");
  garbage.data.resize(100);  // truncated: not decodable
  left_compressed_pub_.publish(garbage);
  right_compressed_pub_.publish(compressed(right_.image, garbage.header.stamp, "right", "png"));
  for (const char* format : {"png", "jpg"}) {
    const ros::Time stamp = ros::Time::now();
    left_compressed_pub_.publish(compressed(left_.image, stamp, "left", format));
    right_compressed_pub_.publish(compressed(right_.image, stamp, "right", format));
    ASSERT_TRUE(answeredAtLeast(stamp)) << format << ": no correspondences";
    EXPECT_EQ(last_->header.stamp, stamp);
    EXPECT_EQ(last_->right_header.frame_id, "right");
    EXPECT_GE(last_->matches.size(), 50u) << format;
  }
  expectNoneAnswered({garbage.header.stamp});
}

TEST_F(FrameToFrameMatcherTest, MatchesEachFrameWithThePreviousOne) {
  const ros::Time first = ros::Time::now();
  frame_pub_.publish(bgrImage(left_.image, first, "camera"));
  ros::WallDuration(0.2).sleep();
  const ros::Time second = first + ros::Duration(0.5);
  frame_pub_.publish(bgrImage(right_.image, second, "camera"));
  ASSERT_TRUE(waitFor([&] { return last_ && last_->right_header.stamp == second; }));
  EXPECT_EQ(last_->header.stamp, first);  // the earlier frame is the left image
  EXPECT_GE(last_->matches.size(), 50u);
  // A frame older than the previous one is refused; the next newer one is matched.
  frame_pub_.publish(bgrImage(left_.image, first, "camera"));
  const ros::Time third = second + ros::Duration(0.5);
  frame_pub_.publish(bgrImage(left_.image, third, "camera"));
  ASSERT_TRUE(waitFor([&] { return last_->right_header.stamp == third; }));
  EXPECT_EQ(last_->header.stamp, second);
  // Each image was described once: the second frame served two pairs, and the third has the
  // first one's pixels (2 of the 4 lookups hit the cache, 2 images described).
  EXPECT_EQ(
      test::diagnosticValue(nh_, "matcher", "features reused", [](double v) { return v >= 2; }),
      2.0);
  EXPECT_EQ(test::diagnosticValue(nh_, "matcher", "images described", [](double) { return true; }),
            2.0);
}

/// image_pipeline's lazy subscription: the images are subscribed only while someone listens to
/// `correspondences` or `matches_image`, and given up when the last listener leaves.
TEST(LazyMatcherTest, SubscribesTheImagesOnlyWhileSomeoneListens) {
  ros::NodeHandle nh;
  ros::Publisher left = nh.advertise<sensor_msgs::Image>("left/image", 1);
  ros::Publisher right = nh.advertise<sensor_msgs::Image>("right/image", 1);
  const auto subscribed = [&] {
    return left.getNumSubscribers() > 0 && right.getNumSubscribers() > 0;
  };
  const auto unsubscribed = [&] {
    return left.getNumSubscribers() == 0 && right.getNumSubscribers() == 0;
  };
  // Long enough for a subscription that would come to come.
  EXPECT_FALSE(waitFor(subscribed, 2.0)) << "the matcher subscribed with nobody listening";
  ros::Subscriber correspondences = nh.subscribe(
      "correspondences", 1, +[](const sift_hull::CorrespondencesConstPtr&) {});
  ASSERT_TRUE(waitFor(subscribed)) << "no subscription for a correspondences listener";
  correspondences.shutdown();
  ASSERT_TRUE(waitFor(unsubscribed)) << "the images stayed subscribed after the last listener left";
  ros::Subscriber drawing = nh.subscribe(
      "matches_image", 1, +[](const sensor_msgs::ImageConstPtr&) {});
  ASSERT_TRUE(waitFor(subscribed)) << "no subscription for a matches_image listener";
  drawing.shutdown();
  EXPECT_TRUE(waitFor(unsubscribed));
}

}  // namespace
}  // namespace sift_hull

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_matcher_node");
  ros::NodeHandle nh;
  return RUN_ALL_TESTS();
}
