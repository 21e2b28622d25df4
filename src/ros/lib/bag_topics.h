#pragma once

namespace sift_hull {

/// Topics and frames of the bags `sift_hull bag` writes, which launch/demo.launch plays.
namespace bag_topics {
constexpr const char* kCameraFrame = "camera";
constexpr const char* kImage = "/camera/image";
constexpr const char* kSilhouette = "/camera/silhouette";
constexpr const char* kCameraInfo = "/camera/camera_info";
constexpr const char* kLeftImage = "/stereo/left/image";
constexpr const char* kRightImage = "/stereo/right/image";
/// camera_info beside each stereo image (image_transport's convention).
constexpr const char* kLeftCameraInfo = "/stereo/left/camera_info";
constexpr const char* kRightCameraInfo = "/stereo/right/camera_info";
/// Frames of the stereo pair; tf places both in the world frame at every stamp.
constexpr const char* kLeftFrame = "left";
constexpr const char* kRightFrame = "right";
}  // namespace bag_topics

}  // namespace sift_hull
