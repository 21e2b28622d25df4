#pragma once

#include <string>
#include <vector>

#include "sift_hull/geometry/camera_set.h"
#include "sift_hull/io/calibration.h"

namespace sift_hull {

/// Orients the cameras of views read from projection matrices (orientCameras): each P's sign is
/// chosen so that the scene, where the optical axes meet, lies in front of the camera; a mirrored
/// (left-handed) world gives improper cameras. Throws ParseError for `path` naming the views that
/// cannot be oriented consistently with the others.
CameraOrientation orientViews(std::vector<CalibratedView>* views, const std::string& path);

}  // namespace sift_hull
