// The bag command: a synthetic scene written as a bag holds, per view, tf, the image, the
// silhouette, camera_info and a stereo pair, with the scene's cameras.

#include <gtest/gtest.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <tf2_msgs/TFMessage.h>

#include <fstream>
#include <iomanip>
#include <map>

#include "common/test_data.h"
#include "sift_hull/io/calibration.h"

namespace sift_hull {
namespace {

TEST(BagCommand, WritesEveryViewOfASceneWithItsCamera) {
  const std::string dir = test::temporaryDirectory();
  std::string out, err;
  ASSERT_EQ(test::runProgram("scene --out " + dir + " --views 4 --size 160x120", &out, &err), 0)
      << err;
  ASSERT_EQ(test::runRosProgram("bag --calib " + dir + "/scene_par.txt --images " + dir +
                                    " --silhouettes " + dir + "/masks --rate 4 --out " + dir +
                                    "/scene.bag",
                                &out, &err),
            0)
      << err;
  const std::vector<CalibratedView> views = readCalibration(dir + "/scene_par.txt");
  rosbag::Bag bag(dir + "/scene.bag", rosbag::bagmode::Read);
  std::map<std::string, int> counts;
  std::map<std::string, int> info_index;
  for (const rosbag::MessageInstance& message : rosbag::View(bag)) {
    ++counts[message.getTopic()];
    if (const auto info = message.instantiate<sensor_msgs::CameraInfo>()) {
      // The right image of the pair is the next view round the ring.
      const int index = info_index[message.getTopic()]++;
      const bool right = message.getTopic() == "/stereo/right/camera_info";
      EXPECT_EQ(info->width, 160u);
      EXPECT_NEAR(info->K[0], views[(index + right) % 4].camera.K()(0, 0), 1e-9);
      EXPECT_NEAR(info->header.stamp.toSec(), 1.0 + 0.25 * index, 1e-9);
      EXPECT_EQ(info->header.frame_id, message.getTopic() == "/camera/camera_info" ? "camera"
                                       : right                                     ? "right"
                                                                                   : "left");
    }
    if (message.getTopic() == "/camera/silhouette") {
      EXPECT_EQ(message.instantiate<sensor_msgs::Image>()->encoding, "mono8");
    }
    if (const auto tf = message.instantiate<tf2_msgs::TFMessage>()) {
      ASSERT_EQ(tf->transforms.size(), 3u);
      const int v = counts["/tf"] - 1;
      const Eigen::Vector3d centre = views[v].camera.centre();
      EXPECT_NEAR(tf->transforms[0].transform.translation.x, centre.x(), 1e-9);
      EXPECT_EQ(tf->transforms[0].child_frame_id, "camera");
      EXPECT_EQ(tf->transforms[1].child_frame_id, "left");
      EXPECT_EQ(tf->transforms[2].child_frame_id, "right");
      EXPECT_NEAR(tf->transforms[2].transform.translation.y, views[(v + 1) % 4].camera.centre().y(),
                  1e-9);
    }
  }
  for (const char* topic :
       {"/tf", "/camera/image", "/camera/silhouette", "/camera/camera_info", "/stereo/left/image",
        "/stereo/right/image", "/stereo/left/camera_info", "/stereo/right/camera_info"}) {
    EXPECT_EQ(counts[topic], 4) << topic;
  }
}

TEST(BagCommand, RefusesAMirroredWorldNamingTheView) {
  const std::string dir = test::temporaryDirectory();
  std::string out, err;
  ASSERT_EQ(test::runProgram("scene --out " + dir + " --views 4 --size 160x120", &out, &err), 0)
      << err;
  // Every P times diag(-1, 1, 1, 1): the scene's world with its x axis negated.
  std::ofstream list(dir + "/mirrored.txt");
  list << std::setprecision(17);
  for (const CalibratedView& view : readCalibration(dir + "/scene_par.txt")) {
    const Matrix34d P =
        view.camera.projectionMatrix() * Eigen::Vector4d(-1.0, 1.0, 1.0, 1.0).asDiagonal();
    list << view.name;
    for (int i = 0; i < 12; ++i) list << ' ' << P(i / 4, i % 4);
    list << '\n';
  }
  list.close();
  EXPECT_EQ(test::runRosProgram("bag --calib " + dir + "/mirrored.txt --images " + dir +
                                    " --silhouettes " + dir + "/masks --out " + dir + "/m.bag",
                                &out, &err),
            1);
  EXPECT_NE(err.find("view_0000.png: the calibration's world frame is mirrored (det R = -1)"),
            std::string::npos)
      << err;
}

}  // namespace
}  // namespace sift_hull
