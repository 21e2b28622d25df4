# The sources of the ROS-free libraries, relative to the package root, one list per layer:
#   sift_hull_core   geometry, features, filters, hull: the method itself
#   sift_hull_io     calibration files, images, PFM, PLY, view lists, ground-truth files
#   sift_hull_pipeline  the pair pipeline and the matches refinement, the match drawings
#   sift_hull_eval   the synthetic renderer and the evaluation against ground truth
# Included by the package's CMakeLists.txt and by test/sanitize/CMakeLists.txt, so that both build
# the libraries from the same lists (docs/ARCHITECTURE.md).
set(SIFT_HULL_CORE_SOURCES
  src/core/common/settings.cpp
  src/core/geometry/camera.cpp
  src/core/geometry/camera_set.cpp
  src/core/geometry/correspondence.cpp
  src/core/geometry/distortion.cpp
  src/core/features/byte_neighbours.cpp
  src/core/features/feature_cache.cpp
  src/core/features/matching.cpp
  src/core/features/nearest_neighbours.cpp
  src/core/features/sift.cpp
  src/core/features/triangulation.cpp
  src/core/filters/densest_window.cpp
  src/core/filters/epipolar.cpp
  src/core/filters/filter.cpp
  src/core/filters/filter_settings.cpp
  src/core/filters/gms.cpp
  src/core/filters/gsc.cpp
  src/core/filters/guided.cpp
  src/core/filters/local_consistency.cpp
  src/core/filters/ratio.cpp
  src/core/filters/robust_fit.cpp
  src/core/filters/spatial_neighbours.cpp
  src/core/filters/two_view_fit.cpp
  src/core/filters/two_view_models.cpp
  src/core/filters/vote_ransac.cpp
  src/core/hull/bounding_box.cpp
  src/core/hull/distance_kernel.cpp
  src/core/hull/distance_map.cpp
  src/core/hull/field_sampling.cpp
  src/core/hull/hull_octomap.cpp
  src/core/hull/hull_pipeline.cpp
  src/core/hull/hull_settings.cpp
  src/core/hull/hull_stream.cpp
  src/core/hull/hull_view.cpp
  src/core/hull/marching_cubes.cpp
  src/core/hull/mesh.cpp
  src/core/hull/compact_octomap.cpp
  src/core/hull/hull_cube.cpp
  src/core/hull/octree.cpp
  src/core/hull/free_carving.cpp
  src/core/hull/reduced_distance_map.cpp
  src/core/hull/run_length_mask.cpp
  src/core/hull/silhouette.cpp
  src/core/mvs/depth_maps.cpp
  src/core/mvs/mesh_colour.cpp
  src/core/mvs/patch_match.cpp
  src/core/mvs/photo_carving.cpp
  src/core/mvs/photo_stream.cpp
  src/core/refine/dense_matching.cpp
  src/core/refine/free_space.cpp
  src/core/refine/point_carved_stream.cpp
  src/core/refine/refine_settings.cpp
  src/core/refine/surface_points.cpp
)
set(SIFT_HULL_IO_SOURCES
  src/core/io/calibration.cpp
  src/core/io/colmap.cpp
  src/core/io/colmap_text.cpp
  src/core/io/colmap_writer.cpp
  src/core/io/ground_truth_files.cpp
  src/core/io/images.cpp
  src/core/io/llff.cpp
  src/core/io/nerf.cpp
  src/core/io/pfm.cpp
  src/core/io/ply.cpp
  src/core/io/view_list.cpp
  src/core/io/view_orientation.cpp
)
set(SIFT_HULL_PIPELINE_SOURCES
  src/core/draw/match_drawing.cpp
  src/core/pipeline/match_refinement.cpp
  src/core/pipeline/pair_pipeline.cpp
)
set(SIFT_HULL_EVAL_SOURCES
  src/core/synthetic/mask_render.cpp
  src/core/synthetic/scene.cpp
  src/core/synthetic/scene_match.cpp
  src/core/synthetic/scene_support.cpp
  src/core/synthetic/shape.cpp
  src/core/synthetic/synthetic_matches.cpp
  src/core/synthetic/texture.cpp
  src/core/synthetic/warped_pairs.cpp
  src/core/eval/hull_evaluation.cpp
  src/core/eval/match_evaluation.cpp
  src/core/eval/mesh_render.cpp
)
# No contraction into fused multiply-adds: the GSC kernel's sectors must not depend on which vector
# width the CPU dispatch picks, the scalar and AVX2 distance look-ups must round alike, and the
# two-view residual kernels (vote_ransac) must score a model alike on every CPU.
set(SIFT_HULL_EXACT_FLOAT_SOURCES
  src/core/filters/densest_window.cpp
  src/core/filters/gsc.cpp
  src/core/filters/guided.cpp
  src/core/filters/local_consistency.cpp
  src/core/filters/two_view_fit.cpp
  src/core/filters/two_view_models.cpp
  src/core/filters/vote_ransac.cpp
  src/core/hull/distance_kernel.cpp
)
