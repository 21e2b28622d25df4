// The hull node's outputs: octomap_server's topics and services, the markers and the mesh.

#include <sstream>

#include "lib/conversions.h"
#include "nodes/hull_node.h"
#include "sift_hull/hull/hull_octomap.h"

namespace sift_hull {
namespace {

std::string pointText(const geometry_msgs::Point& point) {
  std::ostringstream out;
  out << "(" << point.x << ", " << point.y << ", " << point.z << ")";
  return out.str();
}

visualization_msgs::MarkerArray deleteAllMarkers(const std_msgs::Header& header) {
  visualization_msgs::Marker delete_all;
  delete_all.header = header;
  delete_all.action = visualization_msgs::Marker::DELETEALL;
  visualization_msgs::MarkerArray markers;
  markers.markers.push_back(delete_all);
  return markers;
}

}  // namespace

void HullNode::advertiseServices() {
  reset_srv_ = private_nh_.advertiseService("reset", &HullNode::reset, this);
  save_srv_ = private_nh_.advertiseService("save", &HullNode::save, this);
  // octomap_server's names: the maps in the node's namespace, clearing private.
  binary_srv_ =
      nh_.advertiseService<sift_hull::GetOctomap::Request, sift_hull::GetOctomap::Response>(
          "octomap_binary",
          [this](sift_hull::GetOctomap::Request&, sift_hull::GetOctomap::Response& response) {
            return getMap(true, &response);
          });
  full_srv_ = nh_.advertiseService<sift_hull::GetOctomap::Request, sift_hull::GetOctomap::Response>(
      "octomap_full",
      [this](sift_hull::GetOctomap::Request&, sift_hull::GetOctomap::Response& response) {
        return getMap(false, &response);
      });
  clear_bbx_srv_ = private_nh_.advertiseService("clear_bbx", &HullNode::clearBbx, this);
}

void HullNode::publish(const ros::Time& stamp) {
  header_.stamp = stamp;
  header_.frame_id = config_.world_frame;
  published_ = true;
  tree_stale_ = true;  // built when first needed (publishedTree)
  mesh_.reset();
  if (mapSubscribers() > 0) publishMaps();
  if (mesh_pub_.getNumSubscribers() > 0) {
    mesh_pub_.publish(ros_conversions::meshMarker(publishedMesh(), header_));
  }
}

uint32_t HullNode::mapSubscribers() const {
  return octomap_pub_.getNumSubscribers() + octomap_full_pub_.getNumSubscribers() +
         cloud_pub_.getNumSubscribers() + centers_pub_.getNumSubscribers() +
         markers_pub_.getNumSubscribers() + free_markers_pub_.getNumSubscribers();
}

const octomap::OcTree& HullNode::publishedTree() {
  if (!octree_ || tree_stale_) {
    octree_ = toOctomap(stream_.hull());
    for (const Box3d& box : cleared_boxes_) clearBox(box, octree_.get());
    tree_stale_ = false;
  }
  return *octree_;
}

/// Each map topic someone subscribes (a latched topic nobody listens to costs no conversion; its
/// first subscriber gets the map at once: publishMapsNow).
void HullNode::publishMaps() {
  const bool binary = octomap_pub_.getNumSubscribers() > 0;
  const bool centres = cloud_pub_.getNumSubscribers() + centers_pub_.getNumSubscribers() > 0;
  if ((binary || centres) && cleared_boxes_.empty()) {
    // What every view publishes, from the compact map (no OctoMap nodes); OctoMap's own tree
    // only for what needs it (the full map, markers, cleared boxes, services, ~save).
    const CompactOctomap map = compactOctomap(stream_.hull());
    if (binary) octomap_pub_.publish(ros_conversions::octomapMessage(map, header_));
    if (centres)
      publishCentres(ros_conversions::pointCloudMessage(map.occupied_centres_W, header_));
  } else if (binary || centres) {
    const octomap::OcTree& tree = publishedTree();
    if (binary) octomap_pub_.publish(ros_conversions::octomapMessage(tree, header_));
    if (centres) publishCentres(ros_conversions::occupiedCellsCloud(tree, header_));
  }
  if (octomap_full_pub_.getNumSubscribers() > 0) {  // its data is about 10 times the binary's
    octomap_full_pub_.publish(ros_conversions::octomapFullMessage(publishedTree(), header_));
  }
  if (markers_pub_.getNumSubscribers() > 0) {
    markers_pub_.publish(ros_conversions::occupiedCellsMarkers(publishedTree(), header_));
  }
  if (free_markers_pub_.getNumSubscribers() > 0) {
    free_markers_pub_.publish(ros_conversions::freeCellsMarkers(publishedTree(), header_));
  }
}

void HullNode::publishCentres(const sensor_msgs::PointCloud2& centres) {
  cloud_pub_.publish(centres);
  centers_pub_.publish(centres);
}

void HullNode::publishMapsNow() {
  std::lock_guard<std::mutex> lock(hull_mutex_);
  if (published_) publishMaps();
}

const TriangleMesh& HullNode::publishedMesh() {
  if (!mesh_) mesh_ = std::make_unique<TriangleMesh>(stream_.hull().mesh());
  return *mesh_;
}

void HullNode::publishMarkersNow() {
  std::lock_guard<std::mutex> lock(hull_mutex_);
  if (published_) {
    markers_pub_.publish(ros_conversions::occupiedCellsMarkers(publishedTree(), header_));
  }
}

void HullNode::publishFullNow() {
  std::lock_guard<std::mutex> lock(hull_mutex_);
  if (published_) {
    octomap_full_pub_.publish(ros_conversions::octomapFullMessage(publishedTree(), header_));
  }
}

void HullNode::publishFreeMarkersNow() {
  std::lock_guard<std::mutex> lock(hull_mutex_);
  if (published_) {
    free_markers_pub_.publish(ros_conversions::freeCellsMarkers(publishedTree(), header_));
  }
}

void HullNode::publishMeshNow() {
  std::lock_guard<std::mutex> lock(hull_mutex_);
  if (published_) mesh_pub_.publish(ros_conversions::meshMarker(publishedMesh(), header_));
}

/// An empty map at the last resolution, and markers deleted.
void HullNode::publishEmpty() {
  header_.stamp = ros::Time::now();
  header_.frame_id = config_.world_frame;
  const octomap::OcTree empty(octree_ ? octree_->getResolution() : 0.1);
  octomap_pub_.publish(ros_conversions::octomapMessage(empty, header_));
  octomap_full_pub_.publish(ros_conversions::octomapFullMessage(empty, header_));
  const sensor_msgs::PointCloud2 centres = ros_conversions::occupiedCellsCloud(empty, header_);
  cloud_pub_.publish(centres);
  centers_pub_.publish(centres);
  const visualization_msgs::MarkerArray delete_all = deleteAllMarkers(header_);
  markers_pub_.publish(delete_all);
  free_markers_pub_.publish(delete_all);
  mesh_pub_.publish(delete_all.markers.front());
}

bool HullNode::getMap(bool binary, sift_hull::GetOctomap::Response* response) {
  std::lock_guard<std::mutex> lock(hull_mutex_);
  if (!published_) {
    log_.error(binary ? "hull: octomap_binary refused: " : "hull: octomap_full refused: ",
               "no map yet (no view carved since the start or ~reset)");
    return false;
  }
  response->map = binary ? ros_conversions::octomapMessage(publishedTree(), header_)
                         : ros_conversions::octomapFullMessage(publishedTree(), header_);
  return true;
}

bool HullNode::clearBbx(sift_hull::BoundingBoxQuery::Request& request,
                        sift_hull::BoundingBoxQuery::Response&) {
  const Box3d box = ros_conversions::boxFromCorners(request.min, request.max);
  if (!isValidClearBox(box)) {
    log_.error("hull: ~clear_bbx refused: ", "min " + pointText(request.min) + " and max " +
                                                 pointText(request.max) +
                                                 " must be finite with min <= max on each axis");
    return false;
  }
  std::lock_guard<std::mutex> lock(hull_mutex_);
  cleared_boxes_.push_back(box);  // applied to every later map too, until ~reset
  if (!published_) {
    ROS_INFO("hull: ~clear_bbx: no map yet; the box will be cleared in the first one");
    return true;
  }
  publishedTree();  // built with every cleared box, or brought up to date here
  clearBox(box, octree_.get());
  header_.stamp = ros::Time::now();
  publishMaps();
  ROS_INFO("hull: ~clear_bbx: cleared %s to %s", pointText(request.min).c_str(),
           pointText(request.max).c_str());
  return true;
}

}  // namespace sift_hull
