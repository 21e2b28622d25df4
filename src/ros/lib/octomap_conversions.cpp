// The conversions of conversions.h between OctoMap trees and messages.

#include <octomap/ColorOcTree.h>
#include <octomap/OcTree.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl_conversions/pcl_conversions.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

#include "lib/conversions.h"
#include "sift_hull/hull/hull_octomap.h"

namespace sift_hull {
namespace ros_conversions {

namespace {

/// An OcTree's message: binary (OctoMap's binary stream) or full, `bytes` its data.
sift_hull::Octomap mapMessage(const std_msgs::Header& header, bool binary, double resolution_m,
                              const std::string& bytes, const std::string& id = "OcTree") {
  sift_hull::Octomap message;
  message.header = header;
  message.binary = binary;
  message.id = id;
  message.resolution = resolution_m;
  message.data.assign(bytes.begin(), bytes.end());
  return message;
}

}  // namespace

sift_hull::Octomap octomapMessage(const octomap::OcTree& tree, const std_msgs::Header& header) {
  std::stringstream stream;
  writeOctomapBinaryData(tree, stream);
  return mapMessage(header, true, tree.getResolution(), stream.str());
}

sift_hull::Octomap octomapMessage(const CompactOctomap& map, const std_msgs::Header& header) {
  return mapMessage(header, true, map.resolution_m, map.binary_data);
}

sift_hull::Octomap octomapFullMessage(const octomap::OcTree& tree, const std_msgs::Header& header) {
  std::stringstream stream;
  tree.writeData(stream);
  return mapMessage(header, false, tree.getResolution(), stream.str());
}

sift_hull::Octomap octomapFullMessage(const octomap::ColorOcTree& tree,
                                      const std_msgs::Header& header) {
  std::stringstream stream;
  tree.writeData(stream);
  return mapMessage(header, false, tree.getResolution(), stream.str(), "ColorOcTree");
}

std::unique_ptr<octomap::OcTree> octreeFromMessage(const sift_hull::Octomap& message) {
  if (message.id != "OcTree") {
    throw std::invalid_argument("an Octomap message of id '" + message.id + "', not 'OcTree'");
  }
  if (!(message.resolution > 0.0) || !std::isfinite(message.resolution)) {
    throw std::invalid_argument("an Octomap message of resolution " +
                                std::to_string(message.resolution) + " m");
  }
  auto tree = std::make_unique<octomap::OcTree>(message.resolution);
  if (message.data.empty()) return tree;  // an empty tree writes no data
  std::stringstream data(std::string(message.data.begin(), message.data.end()));
  if (message.binary) {
    tree->readBinaryData(data);
  } else {
    tree->readData(data);
  }
  if (data.fail()) throw std::invalid_argument("an Octomap message whose data is cut short");
  return tree;
}

sensor_msgs::PointCloud2 pointCloudMessage(const std::vector<Eigen::Vector3d>& points,
                                           const std_msgs::Header& header) {
  pcl::PointCloud<pcl::PointXYZ> cloud;
  for (const Eigen::Vector3d& point : points) {
    cloud.push_back(pcl::PointXYZ(point.x(), point.y(), point.z()));
  }
  sensor_msgs::PointCloud2 message;
  pcl::toROSMsg(cloud, message);
  message.header = header;
  return message;
}

sensor_msgs::PointCloud2 pointCloudMessage(const std::vector<Eigen::Vector3d>& points,
                                           const std::vector<std::array<uint8_t, 3>>& colours_rgb,
                                           const std_msgs::Header& header) {
  if (colours_rgb.size() != points.size()) {
    throw std::invalid_argument("a coloured cloud of " + std::to_string(points.size()) +
                                " points and " + std::to_string(colours_rgb.size()) + " colours");
  }
  pcl::PointCloud<pcl::PointXYZRGB> cloud;
  cloud.reserve(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    pcl::PointXYZRGB point(colours_rgb[i][0], colours_rgb[i][1], colours_rgb[i][2]);
    point.x = static_cast<float>(points[i].x());
    point.y = static_cast<float>(points[i].y());
    point.z = static_cast<float>(points[i].z());
    cloud.push_back(point);
  }
  sensor_msgs::PointCloud2 message;
  pcl::toROSMsg(cloud, message);
  message.header = header;
  return message;
}

sensor_msgs::PointCloud2 occupiedCellsCloud(const octomap::OcTree& tree,
                                            const std_msgs::Header& header) {
  std::vector<Eigen::Vector3d> centres;
  for (auto leaf = tree.begin_leafs(); leaf != tree.end_leafs(); ++leaf) {
    if (tree.isNodeOccupied(*leaf)) centres.emplace_back(leaf.getX(), leaf.getY(), leaf.getZ());
  }
  return pointCloudMessage(centres, header);
}

namespace {

/// octomap_server's colour of free cells: blue, opaque.
std_msgs::ColorRGBA freeColour() {
  std_msgs::ColorRGBA colour;
  colour.b = 1.0f, colour.a = 1.0f;
  return colour;
}

std_msgs::ColorRGBA heightColour(double fraction) {
  std_msgs::ColorRGBA colour;
  colour.r = static_cast<float>(std::clamp(1.5 - std::abs(4.0 * fraction - 3.0), 0.0, 1.0));
  colour.g = static_cast<float>(std::clamp(1.5 - std::abs(4.0 * fraction - 2.0), 0.0, 1.0));
  colour.b = static_cast<float>(std::clamp(1.5 - std::abs(4.0 * fraction - 1.0), 0.0, 1.0));
  colour.a = 1.0f;
  return colour;
}

/// octomap_server's layout: one CUBE_LIST per depth level 0..tree depth (id = level), in
/// namespace `ns`, of the occupied (or free) leaves at that level; a level without such leaves is
/// sent with action DELETE so rviz drops what it showed there before (after a re-root or a reset).
/// Occupied cells are coloured by height, free ones all `freeColour()`.
visualization_msgs::MarkerArray cellsMarkers(const octomap::OcTree& tree,
                                             const std_msgs::Header& header, bool occupied,
                                             const std::string& ns) {
  double min_x, min_y, min_z, max_x, max_y, max_z;
  tree.getMetricMin(min_x, min_y, min_z);
  tree.getMetricMax(max_x, max_y, max_z);
  const double height = std::max(max_z - min_z, 1e-9);
  visualization_msgs::MarkerArray array;
  array.markers.resize(static_cast<size_t>(tree.getTreeDepth()) + 1);
  for (auto leaf = tree.begin_leafs(); leaf != tree.end_leafs(); ++leaf) {
    if (tree.isNodeOccupied(*leaf) != occupied) continue;
    visualization_msgs::Marker& marker = array.markers.at(leaf.getDepth());
    geometry_msgs::Point centre;
    centre.x = leaf.getX(), centre.y = leaf.getY(), centre.z = leaf.getZ();
    marker.points.push_back(centre);
    if (occupied) marker.colors.push_back(heightColour((centre.z - min_z) / height));
  }
  for (size_t depth = 0; depth < array.markers.size(); ++depth) {
    visualization_msgs::Marker& marker = array.markers[depth];
    marker.header = header;
    marker.ns = ns;
    marker.id = static_cast<int>(depth);
    marker.type = visualization_msgs::Marker::CUBE_LIST;
    marker.action = marker.points.empty() ? visualization_msgs::Marker::DELETE
                                          : visualization_msgs::Marker::ADD;
    marker.scale.x = marker.scale.y = marker.scale.z =
        tree.getNodeSize(static_cast<unsigned>(depth));
    marker.pose.orientation.w = 1.0;
    if (!occupied) marker.color = freeColour();
  }
  return array;
}

}  // namespace

visualization_msgs::MarkerArray occupiedCellsMarkers(const octomap::OcTree& tree,
                                                     const std_msgs::Header& header) {
  return cellsMarkers(tree, header, true, "occupied_cells");
}

visualization_msgs::MarkerArray freeCellsMarkers(const octomap::OcTree& tree,
                                                 const std_msgs::Header& header) {
  return cellsMarkers(tree, header, false, "free_cells");
}

visualization_msgs::MarkerArray deleteAllMarkers(const std_msgs::Header& header) {
  visualization_msgs::Marker delete_all;
  delete_all.header = header;
  delete_all.action = visualization_msgs::Marker::DELETEALL;
  visualization_msgs::MarkerArray markers;
  markers.markers.push_back(delete_all);
  return markers;
}

Box3d boxFromCorners(const geometry_msgs::Point& min, const geometry_msgs::Point& max) {
  return {Eigen::Vector3d(min.x, min.y, min.z), Eigen::Vector3d(max.x, max.y, max.z)};
}

std::string pointText(const geometry_msgs::Point& point) {
  std::ostringstream out;
  out << "(" << point.x << ", " << point.y << ", " << point.z << ")";
  return out.str();
}

visualization_msgs::Marker boxMarker(const Box3d& box_W, const std_msgs::Header& header) {
  visualization_msgs::Marker marker = ros_conversions::marker(
      header, "carving_box", visualization_msgs::Marker::LINE_LIST, colour(1.0f, 0.85f, 0.0f));
  marker.scale.x = 0.01 * box_W.size().maxCoeff();
  const auto corner = [&box_W](int c) {
    geometry_msgs::Point p;
    p.x = (c & 1) ? box_W.max_W.x() : box_W.min_W.x();
    p.y = (c & 2) ? box_W.max_W.y() : box_W.min_W.y();
    p.z = (c & 4) ? box_W.max_W.z() : box_W.min_W.z();
    return p;
  };
  for (int c = 0; c < 8; ++c) {  // each edge once: from a corner to the one a bit above it
    for (int bit : {1, 2, 4}) {
      if (c & bit) continue;
      marker.points.push_back(corner(c));
      marker.points.push_back(corner(c | bit));
    }
  }
  return marker;
}

}  // namespace ros_conversions
}  // namespace sift_hull
