// bag: calibrated views as a ROS bag that drives both nodes with `rosbag play`.

#include <rosbag/bag.h>
#include <tf2_msgs/TFMessage.h>

#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <stdexcept>

#include "args.h"
#include "commands.h"
#include "hull_options.h"
#include "lib/bag_topics.h"
#include "lib/conversions.h"
#include "sift_hull/hull/hull_pipeline.h"
#include "sift_hull/io/images.h"

namespace sift_hull {
namespace cli {
namespace {

using bag_topics::kCameraFrame;

struct BagView {
  std::string name;
  PinholeCamera camera;
  cv::Mat image, mask;
};

std::vector<BagView> loadViews(const ArgParser& parser) {
  const HullInput input = viewSetFromArgs(parser);
  std::vector<BagView> views;
  for (size_t v = 0; v < input.names.size(); ++v) {
    if (input.cameras[v].improper()) {
      throw std::runtime_error(input.names[v] +
                               ": the calibration's world frame is mirrored (det R = -1), and tf "
                               "holds rotations only: negate one world axis of every P first");
    }
    views.push_back({input.names[v], input.cameras[v],
                     readImage(parser.get("images") + "/" + input.names[v]), input.masks[v]});
  }
  return views;
}

/// The pair (view v, next view round the ring) for the matcher: images, the camera_info beside
/// each, frames "left" and "right". Their poses go to tf with the hull's (writeView): the pair
/// changes with every view, so one static transform between the frames could not hold.
void writeStereoPair(rosbag::Bag* bag, const BagView& left, const BagView& right,
                     const ros::Time& stamp) {
  std_msgs::Header header;
  header.stamp = stamp;
  header.frame_id = bag_topics::kLeftFrame;
  bag->write(bag_topics::kLeftCameraInfo, stamp,
             ros_conversions::cameraInfoMessage(left.camera, left.image.size(), header));
  bag->write(bag_topics::kLeftImage, stamp, ros_conversions::imageMessage(left.image, header));
  header.frame_id = bag_topics::kRightFrame;
  bag->write(bag_topics::kRightCameraInfo, stamp,
             ros_conversions::cameraInfoMessage(right.camera, right.image.size(), header));
  bag->write(bag_topics::kRightImage, stamp, ros_conversions::imageMessage(right.image, header));
}

/// View v at time `stamp`: tf first (world -> camera, left, right), so that the poses are known
/// when the images arrive.
void writeView(rosbag::Bag* bag, const std::vector<BagView>& views, size_t v,
               const ros::Time& stamp, const std::string& world_frame) {
  const BagView& view = views[v];
  const BagView& next = views[(v + 1) % views.size()];
  tf2_msgs::TFMessage tf;
  tf.transforms = {
      ros_conversions::cameraPoseMessage(view.camera, world_frame, kCameraFrame, stamp),
      ros_conversions::cameraPoseMessage(view.camera, world_frame, bag_topics::kLeftFrame, stamp),
      ros_conversions::cameraPoseMessage(next.camera, world_frame, bag_topics::kRightFrame, stamp)};
  bag->write("/tf", stamp, tf);
  std_msgs::Header header;
  header.stamp = stamp;
  header.frame_id = kCameraFrame;
  bag->write(bag_topics::kImage, stamp, ros_conversions::imageMessage(view.image, header));
  bag->write(bag_topics::kSilhouette, stamp, ros_conversions::imageMessage(view.mask, header));
  bag->write(bag_topics::kCameraInfo, stamp,
             ros_conversions::cameraInfoMessage(view.camera, view.mask.size(), header));
  writeStereoPair(bag, view, next, stamp);
}

}  // namespace

int runBag(const std::vector<std::string>& args) {
  ArgParser parser("bag",
                   "Writes calibrated views as a ROS bag for `rosbag play`: per view, tf\n"
                   "(world -> camera, left, right), /camera/image, /camera/silhouette,\n"
                   "/camera/camera_info, and the pair (view, next view) on /stereo/left/image\n"
                   "and /stereo/right/image with /stereo/{left,right}/camera_info beside them\n"
                   "(frames left and right), for the matcher with ~calibrated.");
  addViewSetOptions(&parser);
  parser.addOption("out", "BAG", "bag file to write");
  parser.addOption("rate", "HZ", "views per second", "2");
  parser.addOption("world-frame", "FRAME", "frame of the camera poses", "world");
  parser.addFlag("json", "print the result as one JSON object");
  if (!parser.parse(args)) return 0;
  const double rate = parser.getDouble("rate");
  // Stamps 1 us apart at the most stay distinct; 1000 s apart at the least keep a million views
  // within ros::Time's range.
  if (!(rate >= 1e-3 && rate <= 1e6)) {
    throw UsageError("--rate must lie in [0.001, 1000000] views per second");
  }

  const std::vector<BagView> views = loadViews(parser);
  rosbag::Bag bag(parser.get("out"), rosbag::bagmode::Write);
  const ros::Time start(1.0);
  for (size_t v = 0; v < views.size(); ++v) {
    writeView(&bag, views, v, start + ros::Duration(v / rate), parser.get("world-frame"));
  }
  bag.close();
  const nlohmann::json result = {{"out", parser.get("out")},
                                 {"views", views.size()},
                                 {"duration_s", (views.size() - 1) / rate}};
  std::ostringstream text;
  text << "wrote " << views.size() << " views to " << parser.get("out") << '\n';
  printResult(parser.flag("json"), result, text.str());
  return 0;
}

}  // namespace cli
}  // namespace sift_hull
