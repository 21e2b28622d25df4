// The hull stream's bad-view policy (docs/RELIABILITY.md): a view that cannot be right is refused
// with a reason and the hull stays as if it never came.

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "common/test_data.h"
#include "sift_hull/hull/hull_config.h"
#include "sift_hull/hull/hull_pipeline.h"
#include "sift_hull/hull/hull_stream.h"
#include "sift_hull/hull/octree.h"
#include "sift_hull/synthetic/scene.h"

namespace sift_hull {
namespace {

using test::ring;
using test::streamConfig;

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

/// A leaf-by-leaf summary of a hull: equal summaries of the same cube mean equal trees.
struct HullSummary {
  HullStats stats;
  size_t views;
  bool operator==(const HullSummary& o) const {
    return stats.in_leaves == o.stats.in_leaves && stats.out_leaves == o.stats.out_leaves &&
           stats.surface_leaves == o.stats.surface_leaves &&
           stats.occupied_volume_m3 == o.stats.occupied_volume_m3 && views == o.views;
  }
};
HullSummary summary(const VisualHull& hull) { return {hull.stats(), hull.views().size()}; }

TEST(HullStream, RefusesSilhouettesThatCoverNothingOrEverything) {
  const HullInput input = ring(8);
  HullStream stream(streamConfig(6));
  const cv::Mat black = cv::Mat::zeros(input.masks[0].size(), CV_8UC1);
  const cv::Mat white(input.masks[0].size(), CV_8UC1, cv::Scalar(255));
  EXPECT_EQ(stream.add("black", input.cameras[0], black), HullStream::Outcome::kRefused);
  EXPECT_EQ(stream.waitingViews(), 0u);
  for (size_t i = 0; i < input.masks.size(); ++i) {
    stream.add(input.names[i], input.cameras[i], input.masks[i]);
  }
  ASSERT_TRUE(stream.hasHull());
  const HullSummary before = summary(stream.hull());
  const PinholeCamera other = PinholeCamera::fromCentre(input.cameras[0].K(), input.cameras[0].R(),
                                                        input.cameras[0].centre() * 1.1);
  EXPECT_EQ(stream.add("black", other, black), HullStream::Outcome::kRefused);
  EXPECT_EQ(stream.add("white", other, white), HullStream::Outcome::kRefused);
  EXPECT_TRUE(summary(stream.hull()) == before);
  EXPECT_EQ(stream.refusedViews(), 3u);
  const std::vector<std::string> refusals = stream.takeRefusals();
  ASSERT_EQ(refusals.size(), 3u);
  EXPECT_TRUE(contains(refusals[0], "covers no pixel")) << refusals[0];
  EXPECT_TRUE(contains(refusals[2], "covers the whole image")) << refusals[2];
  EXPECT_TRUE(stream.takeRefusals().empty());
}

TEST(HullStream, RefusesAViewThatWouldCarveTheHullToNothing) {
  const HullInput input = ring(8);
  HullStream stream(streamConfig(6));
  for (size_t i = 0; i < input.masks.size(); ++i) {
    stream.add(input.names[i], input.cameras[i], input.masks[i]);
  }
  ASSERT_TRUE(stream.hasHull());
  const HullSummary before = summary(stream.hull());
  // A blob in the image's corner, where the sphere does not project, seen from a new place.
  cv::Mat corner = cv::Mat::zeros(input.masks[0].size(), CV_8UC1);
  corner(cv::Rect(0, 0, 10, 10)).setTo(255);
  const PinholeCamera other = PinholeCamera::fromCentre(input.cameras[0].K(), input.cameras[0].R(),
                                                        input.cameras[0].centre() * 1.1);
  EXPECT_EQ(stream.add("corner", other, corner), HullStream::Outcome::kRefused);
  EXPECT_TRUE(summary(stream.hull()) == before);
  const std::vector<std::string> refusals = stream.takeRefusals();
  ASSERT_EQ(refusals.size(), 1u);
  EXPECT_TRUE(contains(refusals[0], "carve the hull to nothing")) << refusals[0];
  // A good view after it refines the hull as usual.
  const HullInput more = ring(9);
  EXPECT_EQ(stream.add("more", more.cameras[4], more.masks[4]), HullStream::Outcome::kCarved);
}

TEST(HullStream, WithAGivenBoxAFirstViewThatCarvesItToNothingIsRefused) {
  const HullInput input = ring(8);
  HullStreamConfig config = streamConfig(6);
  config.box = buildHull(input, config.hull).box;
  HullStream without(config), with(config);
  cv::Mat corner = cv::Mat::zeros(input.masks[0].size(), CV_8UC1);
  corner(cv::Rect(0, 0, 10, 10)).setTo(255);
  const PinholeCamera other = PinholeCamera::fromCentre(input.cameras[0].K(), input.cameras[0].R(),
                                                        input.cameras[0].centre() * 1.1);
  EXPECT_EQ(with.add("corner", other, corner), HullStream::Outcome::kRefused);
  EXPECT_FALSE(with.hasHull());
  for (size_t i = 0; i < input.masks.size(); ++i) {
    without.add(input.names[i], input.cameras[i], input.masks[i]);
    with.add(input.names[i], input.cameras[i], input.masks[i]);
  }
  ASSERT_TRUE(with.hasHull());
  EXPECT_TRUE(summary(with.hull()) == summary(without.hull()));
}

/// View 0's camera moved sideways by 3 m along its own x axis: its cone runs beside the others'.
PinholeCamera besideTheOthers(const PinholeCamera& camera) {
  return PinholeCamera::fromCentre(camera.K(), camera.R(),
                                   camera.centre() + 3.0 * camera.R().row(0).transpose());
}

TEST(HullStream, AViewWhoseConeMissesTheOthersIsDroppedAsIfItNeverCame) {
  const HullInput input = ring(8);
  HullStream without(streamConfig(6)), with(streamConfig(6));
  EXPECT_EQ(with.add("beside", besideTheOthers(input.cameras[0]), input.masks[0]),
            HullStream::Outcome::kWaiting);
  for (size_t i = 0; i < input.masks.size(); ++i) {
    without.add(input.names[i], input.cameras[i], input.masks[i]);
    with.add(input.names[i], input.cameras[i], input.masks[i]);
  }
  ASSERT_TRUE(without.hasHull());
  ASSERT_TRUE(with.hasHull()) << with.whyNoBox();
  EXPECT_TRUE(with.hull().cube().box().min_W.isApprox(without.hull().cube().box().min_W));
  EXPECT_TRUE(summary(with.hull()) == summary(without.hull()));
  EXPECT_EQ(with.refusedViews(), 1u);
  const std::vector<std::string> refusals = with.takeRefusals();
  ASSERT_EQ(refusals.size(), 1u);
  EXPECT_TRUE(contains(refusals[0], "'beside'")) << refusals[0];
  EXPECT_TRUE(contains(refusals[0], "misses the other views")) << refusals[0];
}

TEST(HullStream, WaitingIsBoundedByMaxWaitingViews) {
  // Views that never bound a box (one camera turning on the spot) do not pile up.
  const HullInput input = ring(8);
  HullStreamConfig config = streamConfig(6);
  config.max_waiting_views = 4;
  HullStream stream(config);
  for (int i = 0; i < 10; ++i) {
    const Eigen::Matrix3d turn =
        Eigen::AngleAxisd(i * 2.0 * M_PI / 180.0, Eigen::Vector3d::UnitY()).toRotationMatrix();
    const PinholeCamera camera = PinholeCamera::fromCentre(
        input.cameras[0].K(), turn * input.cameras[0].R(), input.cameras[0].centre());
    stream.add("turning_" + std::to_string(i), camera, input.masks[0]);
    EXPECT_LE(stream.waitingViews(), 4u);
  }
  EXPECT_FALSE(stream.hasHull());
  EXPECT_EQ(stream.refusedViews(), 6u);
  EXPECT_TRUE(contains(stream.takeRefusals().front(), "max_waiting_views"));
}

TEST(HullStream, ViewsBeyondMaxViewsAreRefused) {
  const HullInput input = ring(8);
  HullStreamConfig config = streamConfig(6);
  config.max_views = 5;
  HullStream stream(config);
  for (size_t i = 0; i < input.masks.size(); ++i) {
    stream.add(input.names[i], input.cameras[i], input.masks[i]);
  }
  ASSERT_TRUE(stream.hasHull());
  EXPECT_EQ(stream.hull().views().size(), 5u);
  EXPECT_EQ(stream.refusedViews(), 3u);
}

TEST(HullStream, ACameraFarBeyondTheBoxIsRefusedAndTheOthersCarve) {
  const HullInput input = ring(8);
  HullStream stream(streamConfig(6));
  for (size_t i = 0; i < input.masks.size(); ++i) {
    PinholeCamera camera = input.cameras[i];
    if (i == 5) camera = PinholeCamera(camera.K(), camera.R(), Eigen::Vector3d(0, 0, 1e39));
    if (i == 6) camera = PinholeCamera(camera.K(), camera.R(), Eigen::Vector3d(0, 0, 1e307));
    stream.add(input.names[i], camera, input.masks[i]);
  }
  ASSERT_TRUE(stream.hasHull());
  EXPECT_EQ(stream.hull().views().size(), 6u);
  EXPECT_EQ(stream.refusedViews(), 2u);
}

}  // namespace
}  // namespace sift_hull
