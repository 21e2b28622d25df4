# The sources of the ROS-free core library sift_hull_core, relative to the package root.
# Included by the package's CMakeLists.txt and by test/sanitize/CMakeLists.txt, so that both build
# the library from the same list.
set(SIFT_HULL_CORE_SOURCES
  src/core/bounding_box.cpp
  src/core/camera.cpp
  src/core/correspondence.cpp
  src/core/dataset.cpp
  src/core/depth_io.cpp
  src/core/distance_kernel.cpp
  src/core/evaluation.cpp
  src/core/features.cpp
  src/core/filters.cpp
  src/core/gms.cpp
  src/core/gsc.cpp
  src/core/hull_evaluation.cpp
  src/core/hull_octomap.cpp
  src/core/hull_pipeline.cpp
  src/core/hull_stream.cpp
  src/core/hull_view.cpp
  src/core/marching_cubes.cpp
  src/core/match_drawing.cpp
  src/core/matching.cpp
  src/core/mesh.cpp
  src/core/scene.cpp
  src/core/shape.cpp
  src/core/synthetic_matches.cpp
  src/core/texture.cpp
  src/core/visual_hull.cpp
)
