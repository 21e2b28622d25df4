// bench-nodes, the matcher: a 640x480 stereo stream at a given rate and number of workers.

#include "bench_nodes.h"
#include "sift_hull/features/sift.h"

namespace sift_hull {
namespace cli {
namespace bench_nodes {

StereoStream stereoStream(int width_px, int height_px) {
  SceneConfig config;  // 16 views
  config.width_px = width_px;
  config.height_px = height_px;
  StereoStream stream;
  for (const RenderedView& view : renderScene(config)) {
    stream.frames.push_back(ros_conversions::imageMessage(view.image, std_msgs::Header()));
    stream.images.push_back(view.image);
  }
  return stream;
}

SiftCost measureSift(const StereoStream& stream) {
  SiftCost cost;
  std::vector<double> keypoints;
  const size_t frames = std::min<size_t>(stream.images.size(), 4);
  for (size_t f = 0; f < frames; ++f) {
    keypoints.push_back(double(detectSift(stream.images[f]).keypoints.size()));
  }
  cost.keypoints = median(keypoints);
  const int threads = cv::getNumThreads();
  size_t next = 0;
  const auto one = [&] { detectSift(stream.images[next++ % frames]); };
  cv::setNumThreads(1);
  cost.one_thread_ms = medianMs(one, 1500.0, 5);
  cv::setNumThreads(threads);
  cost.all_threads_ms = medianMs(one, 1500.0, 5);
  return cost;
}

class MatcherFeed {
 public:
  MatcherFeed(ros::NodeHandle& nh, const StereoStream& stream)
      : stream_(stream),
        left_(nh.advertise<sensor_msgs::Image>("left/image", 2)),
        right_(nh.advertise<sensor_msgs::Image>("right/image", 2)) {}

  bool connected() const { return left_.getNumSubscribers() > 0 && right_.getNumSubscribers() > 0; }
  ros::Time publish(int k, const std::string& frame_suffix = "") {
    const size_t n = stream_.frames.size();
    sensor_msgs::Image left = stream_.frames[k % n], right = stream_.frames[(k + 1) % n];
    left.header.stamp = right.header.stamp = ros::Time::now();
    left.header.frame_id = "left" + frame_suffix;
    right.header.frame_id = "right" + frame_suffix;
    left_.publish(left);
    right_.publish(right);
    return left.header.stamp;
  }

 private:
  const StereoStream& stream_;
  ros::Publisher left_, right_;
};

using SendTimes = std::map<ros::Time, ros::WallTime>;

/// Sends pairs at `run->input_hz` for `seconds`, sampling the node's memory; when each was sent.
SendTimes streamPairs(MatcherFeed& feed, pid_t pid, double seconds, MatcherRun* run) {
  SendTimes sent;
  const ros::WallTime start = ros::WallTime::now();
  for (int k = 0; (ros::WallTime::now() - start).toSec() < seconds; ++k) {
    const ros::WallTime due = start + ros::WallDuration(k / run->input_hz);
    sleepUntilWall(due);
    sent[feed.publish(k)] = ros::WallTime::now();
    const double rss = residentMiB(pid);
    if (run->rss_first_mib == 0.0 && (ros::WallTime::now() - start).toSec() > 1.0) {
      run->rss_first_mib = rss;
    }
    run->rss_max_mib = std::max(run->rss_max_mib, rss);
  }
  return sent;
}

/// Answered rate (from the first pair sent to the last answer) and median latency.
void summariseAnswers(const SendTimes& sent, const ArrivalLog<sift_hull::Correspondences>& answers,
                      MatcherRun* run) {
  std::vector<double> latencies;
  const ros::WallTime start = sent.begin()->second;
  ros::WallTime last_answer = start;
  for (const auto& [stamp, when] : sent) {
    const std::optional<ros::WallTime> arrival = answers.arrival(stamp);
    if (!arrival) continue;
    latencies.push_back((*arrival - when).toSec() * 1e3);
    last_answer = std::max(last_answer, *arrival);
  }
  run->answered = static_cast<int>(latencies.size());
  run->answered_per_s = run->answered / std::max((last_answer - start).toSec(), 1e-9);
  run->latency_ms = median(latencies);
}

MatcherRun runMatcher(RosHarness& harness, const StereoStream& stream, int workers, double input_hz,
                      double seconds) {
  const pid_t pid = harness.startNode(
      "matcher_node", nodeArguments("matcher", {"_workers:=" + std::to_string(workers)}));
  ros::NodeHandle nh;
  MatcherFeed feed(nh, stream);
  ArrivalLog<sift_hull::Correspondences> answers(nh, "correspondences");
  DiagnosticsListener diagnostics(nh, "matcher");
  if (!waitUntil([&] { return feed.connected() && answers.connected(); })) {
    throw std::runtime_error("bench-nodes: matcher_node did not connect");
  }
  for (int k = 0; k < 2; ++k) {  // warm-up, answered one by one
    const ros::Time stamp = feed.publish(k);
    waitUntil([&] { return answers.arrival(stamp).has_value(); });
  }
  MatcherRun run{workers, input_hz, stream.images.front().cols, stream.images.front().rows};
  run.rss_idle_mib = residentMiB(pid);
  const SendTimes sent = streamPairs(feed, pid, seconds, &run);
  run.published = static_cast<int>(sent.size());
  waitUntil(
      [&] {
        const double settled =
            diagnostics.value("pairs processed") + diagnostics.value("pairs dropped");
        return settled >= run.published + 2;  // and the two of the warm-up
      },
      10.0);
  run.rss_last_mib = residentMiB(pid);
  run.dropped = diagnostics.value("pairs dropped");
  run.described = diagnostics.value("images described");
  run.reused = diagnostics.value("features reused");
  summariseAnswers(sent, answers, &run);
  ros::WallDuration(10.0).sleep();  // what a user sees once the stream has ended
  run.rss_10s_after_mib = residentMiB(pid);
  harness.stopNode(pid);
  return run;
}

}  // namespace bench_nodes
}  // namespace cli
}  // namespace sift_hull
