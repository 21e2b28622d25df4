// The hull node's outputs: octomap_server's topics and services, the markers and the mesh.

#include <functional>
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
  unpublished_stamp_ = ros::Time();
  last_publish_wall_ = ros::WallTime::now();
  mesh_.reset();
  publishMaps();
  if (mesh_pub_.getNumSubscribers() > 0) {
    mesh_pub_.publish(ros_conversions::meshMarker(publishedMesh(), header_));
  }
}

void HullNode::publishPending() {
  if (!unpublished_stamp_.isZero()) publish(unpublished_stamp_);
}

const octomap::OcTree& HullNode::publishedTree() {
  if (!octree_ || tree_stale_) {
    octree_ = toOctomap(stream_.hull());
    for (const Box3d& box : cleared_boxes_) clearBox(box, octree_.get());
    tree_stale_ = false;
  }
  return *octree_;
}

/// octomap_binary every time (latched: a later subscriber must not get an older map), from the
/// compact map (no OctoMap nodes) unless boxes were cleared; the centres clouds, the full map and
/// the markers only while someone subscribes (a new subscriber is sent the current one at once).
void HullNode::publishMaps() {
  const bool centres = cloud_pub_.getNumSubscribers() > 0 || centers_pub_.getNumSubscribers() > 0;
  if (cleared_boxes_.empty()) {
    const CompactOctomap map = compactOctomap(stream_.hull(), centres);
    octomap_pub_.publish(ros_conversions::octomapMessage(map, header_));
    if (centres) {
      publishCentres(ros_conversions::pointCloudMessage(map.occupied_centres_W, header_));
    }
  } else {
    const octomap::OcTree& tree = publishedTree();
    octomap_pub_.publish(ros_conversions::octomapMessage(tree, header_));
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

const TriangleMesh& HullNode::publishedMesh() {
  if (!mesh_) mesh_ = std::make_unique<TriangleMesh>(stream_.hull().mesh());
  return *mesh_;
}

void HullNode::sendToNewSubscriber(const std::function<void()>& send) {
  std::lock_guard<std::mutex> lock(hull_mutex_);
  try {
    publishPending();  // views carved but not yet published: their map, with their stamp
    if (published_) send();
  } catch (const std::exception& e) {  // e.g. a hull beyond OctoMap's key range
    log_.error("hull: cannot publish the hull: ", e.what());
  }
}

void HullNode::publishCentresNow(ros::Publisher* pub) {
  sendToNewSubscriber(
      [this, pub] { pub->publish(ros_conversions::occupiedCellsCloud(publishedTree(), header_)); });
}

void HullNode::publishMarkersNow() {
  sendToNewSubscriber([this] {
    markers_pub_.publish(ros_conversions::occupiedCellsMarkers(publishedTree(), header_));
  });
}

void HullNode::publishFullNow() {
  sendToNewSubscriber([this] {
    octomap_full_pub_.publish(ros_conversions::octomapFullMessage(publishedTree(), header_));
  });
}

void HullNode::publishFreeMarkersNow() {
  sendToNewSubscriber([this] {
    free_markers_pub_.publish(ros_conversions::freeCellsMarkers(publishedTree(), header_));
  });
}

void HullNode::publishMeshNow() {
  sendToNewSubscriber(
      [this] { mesh_pub_.publish(ros_conversions::meshMarker(publishedMesh(), header_)); });
}

/// An empty map at `resolution_m`, and markers deleted.
void HullNode::publishEmpty(double resolution_m) {
  header_.stamp = ros::Time::now();
  header_.frame_id = config_.world_frame;
  const octomap::OcTree empty(resolution_m);
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
  publishPending();
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
  publishPending();
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
