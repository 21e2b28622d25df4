// The hull node's photo carving (~photo_carve): the photographs taken with the silhouettes, kept
// per view by a PhotoStream whose passes run on their own thread; each pass that ends is carved
// into the hull and colours the outputs on the worker, and the next one starts.

#include <utility>

#include "lib/conversions.h"
#include "nodes/hull_node.h"

namespace sift_hull {

void HullNode::subscribePhotos(const std::string& silhouette_topic) {
  photo_sub_.registerCallback([this](const sensor_msgs::ImageConstPtr& photo) {
    pairing_.arrived(2, photo->header.stamp.toSec(), PairingWatch::Clock::now());
  });
  photo_sync_.connectInput(silhouette_sub_, info_sub_, photo_sub_);
  photo_sync_.registerCallback(&HullNode::onPhotoTriple, this);
  // The photographs through the same transport as the silhouettes (raw, compressed, ...).
  const std::string photo_topic = nh_.resolveName("image");
  if (photo_topic == silhouette_topic) {
    throw std::invalid_argument("~photo_carve: `image` and `silhouette` are the same topic (" +
                                photo_topic + "); with one topic of photographs set ~from_image");
  }
  photo_sub_.subscribe(image_transport_, photo_topic, config_.queue_size,
                       image_transport::TransportHints("raw", ros::TransportHints(), private_nh_));
}

void HullNode::onPhotoTriple(const sensor_msgs::ImageConstPtr& silhouette,
                             const sensor_msgs::CameraInfoConstPtr& info,
                             const sensor_msgs::ImageConstPtr& photo) {
  {
    std::lock_guard<std::mutex> lock(photos_mutex_);
    photos_.emplace_back(silhouette, photo);
    // Those whose silhouettes PoseWait dropped leave with the oldest.
    while (photos_.size() > 2 * static_cast<size_t>(config_.queue_size)) photos_.pop_front();
  }
  onPair(silhouette, info);
}

sensor_msgs::ImageConstPtr HullNode::takePhoto(const sensor_msgs::ImageConstPtr& silhouette) {
  if (config_.from_image) return silhouette;  // the photograph is the image itself
  std::lock_guard<std::mutex> lock(photos_mutex_);
  for (auto it = photos_.begin(); it != photos_.end(); ++it) {
    if (it->first == silhouette) {
      sensor_msgs::ImageConstPtr photo = it->second;
      photos_.erase(it);
      return photo;
    }
  }
  return nullptr;
}

void HullNode::keepPhoto(const Posed& posed, const View& view) {
  std::string why_not = "no photograph paired with it";
  cv::Mat image;
  if (posed.photo) image = ros_conversions::eightBitImage(posed.photo, &why_not);
  if (image.empty()) {
    ++photo_unpaired_;
    problem("hull: photo carving leaves out view '" + view.name + "': ", why_not);
    return;
  }
  try {
    if (!photo_->add(view.name, view.camera, image, view.mask)) {
      ROS_INFO_THROTTLE(5.0,
                        "hull: photo carving keeps %zu views (~photo_max_views); later views "
                        "carve by their silhouettes only",
                        photo_->keptViews());
    }
  } catch (const std::exception& e) {
    ++photo_unpaired_;
    problem("hull: photo carving leaves out a view: ", e.what());
  }
  photo_views_ = photo_->keptViews();
  photo_views_left_out_ = photo_->leftOutViews();
}

void HullNode::startPhotoPass() {
  if (!hull_.stream().hasHull()) return;
  if (photo_->startIfDue(hull_.stream().hull(), hull_.stream().hullGeneration())) {
    photo_pass_running_ = true;
  }
}

void HullNode::takePhotoPass() {
  std::unique_ptr<PhotoStream::Pass> pass = photo_->takeDone();
  photo_pass_running_ = false;
  if (pass && !pass->error.empty()) {
    ++photo_passes_failed_;
    problem("hull: photo carving failed: ", pass->error);
  } else if (pass && hull_.stream().hasHull() &&
             pass->generation == hull_.stream().hullGeneration()) {
    const ros::WallTime start = ros::WallTime::now();
    hull_.carveFree(pass->carving.free_voxels);  // views carved meanwhile keep what they carved
    counts_.free_voxels = hull_.freeVoxelCount();
    outputs_.setColours(std::make_shared<const TriangleMesh>(std::move(pass->mesh)),
                        config_.photo_color_octomap);
    photo_carved_voxels_ = pass->carving.free_voxels.size();
    last_photo_pass_views_ = pass->views;
    last_photo_pass_ms_ = pass->total_ms;
    publish(ros::Time::now());
    last_photo_apply_ms_ = (ros::WallTime::now() - start).toSec() * 1e3;
    ++photo_passes_applied_;
    ROS_INFO(
        "hull: photo carving with %zu views: %zu voxels free, %zu of %zu vertices coloured "
        "(%.0f ms)",
        pass->views, pass->carving.free_voxels.size(), pass->colouring.coloured_vertices,
        pass->colouring.coloured_vertices + pass->colouring.unseen_vertices, pass->total_ms);
  } else if (pass) {
    ++photo_passes_stale_;  // the tree started anew meanwhile: the next pass carves the new one
  }
  if (work_.counts().waiting == 0) startPhotoPass();
}

void HullNode::reportPhotoDiagnostics(diagnostic_updater::DiagnosticStatusWrapper& status) {
  status.add("photo pass running", photo_pass_running_.load() ? "yes" : "no");
  status.add("photo passes applied", photo_passes_applied_.load());
  status.add("photo views of the last pass applied", last_photo_pass_views_.load());
  status.add("photo passes on a tree since replaced", photo_passes_stale_.load());
  status.add("photo passes failed", photo_passes_failed_.load());
  status.add("photo views kept", photo_views_.load());
  status.add("photo views left out (~photo_max_views)", photo_views_left_out_.load());
  status.add("photo views without a photograph", photo_unpaired_.load());
  status.add("last photo pass free voxels", photo_carved_voxels_.load());
  status.add("last photo pass ms", last_photo_pass_ms_.load());
  status.add("last photo pass carve and publish ms", last_photo_apply_ms_.load());
}

}  // namespace sift_hull
