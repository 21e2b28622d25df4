#include "sift_hull/io/view_orientation.h"

#include <stdexcept>

namespace sift_hull {

CameraOrientation orientViews(std::vector<CalibratedView>* views, const std::string& path) {
  std::vector<PinholeCamera> cameras;
  std::vector<std::string> names;
  for (size_t i = 0; i < views->size(); ++i) {
    const CalibratedView& view = (*views)[i];
    cameras.push_back(view.camera);
    names.push_back(view.name.empty() ? view.source : view.name);
  }
  CameraOrientation orientation;
  try {
    orientation = orientCameras(&cameras, names);
  } catch (const std::invalid_argument& e) {
    throw ParseError(path, 0, e.what());
  }
  for (size_t i = 0; i < views->size(); ++i) (*views)[i].camera = cameras[i];
  return orientation;
}

}  // namespace sift_hull
