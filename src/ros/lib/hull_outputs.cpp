#include "lib/hull_outputs.h"

#include <sensor_msgs/PointCloud2.h>
#include <visualization_msgs/MarkerArray.h>

#include <algorithm>

#include "lib/conversions.h"
#include "lib/save_paths.h"
#include "sift_hull/io/ply.h"
#include "sift_hull/mvs/mesh_colour.h"

namespace sift_hull {

HullOutputs::HullOutputs(ros::NodeHandle nh, std::string world_frame, const HullStream* hull,
                         Post post)
    : nh_(nh), world_frame_(std::move(world_frame)), hull_(hull), post_(std::move(post)) {
  header_.frame_id = world_frame_;
}

template <typename Message>
void HullOutputs::add(const std::string& topic, bool lazy, std::function<Message()> hull,
                      std::function<Message()> empty) {
  const size_t index = outputs_.size();
  Output output;
  output.lazy = lazy;
  // Latched, so that a later subscriber gets the newest map; the lazy ones are also sent to each
  // new subscriber, since they are built only while someone looks.
  output.advertise = [this, topic, lazy, index] {
    return lazy ? nh_.advertise<Message>(
                      topic, 1,
                      [this, index](const ros::SingleSubscriberPublisher&) {
                        post_([this, index] { send(index); });
                      },
                      ros::SubscriberStatusCallback(), ros::VoidConstPtr(), true)
                : nh_.advertise<Message>(topic, 1, true);
  };
  output.send = [this, index, hull, empty] {
    outputs_[index].pub.publish(published_ ? hull() : empty());
  };
  outputs_.push_back(std::move(output));
}

void HullOutputs::advertise() {
  using ros_conversions::octomapFullMessage;
  using Cloud = sensor_msgs::PointCloud2;
  using Markers = visualization_msgs::MarkerArray;
  // No reallocation while a subscriber's connect callback reads an entry (nodelets spin while
  // this runs); such a callback sends nothing anyway until a hull is published.
  outputs_.reserve(8);
  const auto centres = [this] { return centresCloud(); };
  const auto noCentres = [this] {
    if (colour_clouds_) return ros_conversions::pointCloudMessage({}, {}, header_);
    return ros_conversions::occupiedCellsCloud(emptyTree(), header_);
  };
  const auto noMarkers = [this] { return ros_conversions::deleteAllMarkers(header_); };
  // octomap_binary: the snapshot publish() made from the compact map (no OctoMap nodes needed).
  const auto binary = [this] { return *binarySnapshot(); };
  add<sift_hull::Octomap>("octomap_binary", false, binary,
                          [this] { return ros_conversions::octomapMessage(emptyTree(), header_); });
  add<sift_hull::Octomap>(
      "octomap_full", true, [this] { return fullMessage(); },
      [this] { return octomapFullMessage(emptyTree(), header_); });
  add<Cloud>("occupied_cells", true, centres, noCentres);
  outputs_.back().centres = true;
  add<Cloud>("octomap_point_cloud_centers", true, centres, noCentres);
  outputs_.back().centres = true;
  add<Markers>(
      "occupied_cells_vis_array", true,
      [this] { return ros_conversions::occupiedCellsMarkers(tree(), header_); }, noMarkers);
  add<Markers>(
      "free_cells_vis_array", true,
      [this] { return ros_conversions::freeCellsMarkers(tree(), header_); }, noMarkers);
  add<visualization_msgs::Marker>(
      "mesh", true, [this] { return ros_conversions::meshMarker(mesh(), header_); },
      [this] { return ros_conversions::deleteAllMarkers(header_).markers.front(); });
  add<visualization_msgs::Marker>(
      "carving_box", false, [this] { return boxMarker(); }, [this] { return boxMarker(); });
  for (Output& output : outputs_) output.pub = output.advertise();
}

void HullOutputs::publish(ros::Time stamp, bool all) {
  header_.stamp = stamp;
  tree_.reset();
  compact_.reset();
  mesh_.reset();
  colour_tree_.reset();
  published_ = hull_->hasHull();
  if (published_) empty_resolution_m_ = hull_->hull().cube().resolution_m;
  const auto sent = [all](const Output& output) {
    return all || !output.lazy || output.pub.getNumSubscribers() > 0;
  };
  centres_wanted_ = std::any_of(outputs_.begin(), outputs_.end(),
                                [&](const Output& o) { return o.centres && sent(o); });
  std::shared_ptr<sift_hull::Octomap> binary, full;
  if (published_) {
    binary = std::make_shared<sift_hull::Octomap>(
        ros_conversions::octomapMessage(compact(centres_wanted_), header_));
    if (keep_full_) {
      full = std::make_shared<sift_hull::Octomap>(fullMessage());
    }
  }
  {
    std::lock_guard<std::mutex> lock(snapshot_mutex_);
    binary_snapshot_ = std::move(binary);
    full_snapshot_ = std::move(full);
    box_text_ = published_ ? boxText(hull_->box()) : std::string();
  }
  for (Output& output : outputs_) {
    if (sent(output)) {
      output.send();
      output.holds_copy = true;
    } else if (output.holds_copy) {
      // A lazy output nobody listens to: advertised anew, so that its latched copy of an older
      // map is gone, and a later subscriber gets only the current one (sent when it connects).
      output.pub.shutdown();  // first: advertising an advertised topic would keep its copy
      output.pub = output.advertise();
      output.holds_copy = false;
    }
  }
}

void HullOutputs::send(size_t output) {
  if (!published_ && !outputs_[output].holds_copy) return;  // nothing was ever sent
  outputs_[output].send();
  outputs_[output].holds_copy = true;
}

std::shared_ptr<const sift_hull::Octomap> HullOutputs::binarySnapshot() const {
  std::lock_guard<std::mutex> lock(snapshot_mutex_);
  return binary_snapshot_;
}

std::string HullOutputs::carvingBoxText() const {
  std::lock_guard<std::mutex> lock(snapshot_mutex_);
  return box_text_;
}

std::shared_ptr<const sift_hull::Octomap> HullOutputs::fullSnapshot() const {
  std::lock_guard<std::mutex> lock(snapshot_mutex_);
  return full_snapshot_;
}

const octomap::OcTree& HullOutputs::tree() {
  if (!tree_) tree_ = toOctomap(hull_->hull());
  return *tree_;
}

void HullOutputs::setColours(std::shared_ptr<const TriangleMesh> mesh, bool colour_full_map) {
  colour_mesh_ = std::move(mesh);
  colour_full_map_ = colour_full_map;
  colour_tree_.reset();
}

const octomap::ColorOcTree& HullOutputs::colourTree() {
  if (!colour_tree_) colour_tree_ = colourOctomap(tree(), *colour_mesh_);
  return *colour_tree_;
}

sensor_msgs::PointCloud2 HullOutputs::centresCloud() {
  const std::vector<Eigen::Vector3d>& centres_W = compact(true).occupied_centres_W;
  if (!colour_mesh_ && !colour_clouds_) {
    return ros_conversions::pointCloudMessage(centres_W, header_);
  }
  // Each centre the colour of the coloured tree's leaf there (the coarse inner leaves: white).
  std::vector<std::array<uint8_t, 3>> colours(centres_W.size(), {255, 255, 255});
  if (!colour_mesh_) return ros_conversions::pointCloudMessage(centres_W, colours, header_);
  const octomap::ColorOcTree& coloured = colourTree();
  for (size_t i = 0; i < centres_W.size(); ++i) {
    const Eigen::Vector3d& c = centres_W[i];
    const octomap::ColorOcTreeNode* node = coloured.search(c.x(), c.y(), c.z());
    if (node == nullptr) continue;
    const octomap::ColorOcTreeNode::Color colour = node->getColor();
    colours[i] = {colour.r, colour.g, colour.b};
  }
  return ros_conversions::pointCloudMessage(centres_W, colours, header_);
}

sift_hull::Octomap HullOutputs::fullMessage() {
  if (colour_mesh_ && colour_full_map_) {
    return ros_conversions::octomapFullMessage(colourTree(), header_);
  }
  return ros_conversions::octomapFullMessage(tree(), header_);
}

const CompactOctomap& HullOutputs::compact(bool centres) {
  if (!compact_ || (centres && !compact_centres_)) {
    compact_ = std::make_unique<CompactOctomap>(compactOctomap(hull_->hull(), centres));
    compact_centres_ = centres;
  }
  return *compact_;
}

const TriangleMesh& HullOutputs::mesh() {
  if (!mesh_) mesh_ = std::make_unique<TriangleMesh>(hull_->hull().mesh());
  return *mesh_;
}

bool HullOutputs::save(const std::string& path, std::string* message) {
  if (!published_) {
    *message = "no hull yet";
    return false;
  }
  try {
    const SavePaths paths = savePaths(path);
    checkRegularTarget(paths.octree);
    checkRegularTarget(paths.mesh);
    writeReplacing(paths.octree,
                   [this](const std::string& file) { writeOctomap(tree(), file, hull_->box()); });
    writeReplacing(paths.mesh, [this](const std::string& file) { writePly(file, mesh()); });
    *message = "wrote " + paths.octree + " and " + paths.mesh;
    return true;
  } catch (const std::exception& e) {
    *message = e.what();
    return false;
  }
}

visualization_msgs::Marker HullOutputs::boxMarker() {
  if (!published_) return ros_conversions::deleteAllMarkers(header_).markers.front();
  return ros_conversions::boxMarker(hull_->box(), header_);
}

}  // namespace sift_hull
