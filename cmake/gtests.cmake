# The gtests of the ROS-free libraries (test/core), each with the one library it links: the layer
# it tests, or sift_hull_eval where its ground truth is the synthetic renderer. Pairs of
# <test name> <library without the sift_hull_ prefix>. Read by the package's CMakeLists.txt and by
# the sanitizer build (test/sanitize), so that both build the same tests.
set(SIFT_HULL_CORE_GTESTS
  test_camera core
  test_distortion core
  test_bounding_box core
  test_gms core
  test_triangulation core
  test_layout core
  test_mesh core
  test_dataset io
  test_colmap io
  test_calibration_formats io
  test_nerf_transforms eval
  test_photo_set_inputs eval
  test_view_silhouettes eval
  test_silhouette_choice eval
  test_idr_cameras eval
  test_ply io
  test_ground_truth_files io
  test_features eval
  test_nearest_neighbours eval
  test_feature_cache core
  test_filters eval
  test_local_filters eval
  test_two_view_models eval
  test_scaled_residuals eval
  test_colmap_verification eval
  test_vote_ransac eval
  test_filter_ranges eval
  test_densest_window core
  test_evaluation eval
  test_evaluation_commands eval
  test_scene eval
  test_cut_shapes eval
  test_photo_carving eval
  test_photo_stream eval
  test_scene_backgrounds eval
  test_scene_support eval
  test_silhouettes eval
  test_mesh_render eval
  test_hull eval
  test_carving_box_file core
  test_free_carving eval
  test_point_carved_stream eval
  test_refine eval
  test_dense_matching eval
  test_refine_command eval
  test_pair_pipeline eval
  test_reduced_distance eval
  test_reduced_input eval
  test_reduced_photographs eval
  test_hull_data eval
  test_hull_stream eval
  test_hull_stream_refusals eval
  test_hardening eval
  test_cli_output eval
  test_mirrored_world eval
  test_distorted_scene eval
)
# The libFuzzer harnesses of test/fuzz, file test/fuzz/fuzz_<name>.cpp; test_fuzz_corpus replays
# their corpus through them, each entry point renamed fuzz_<name>.
set(SIFT_HULL_FUZZ_HARNESSES middlebury_par projection_list homography pfm ply bounding_box
  colmap_binary npy nerf_transforms idr_cameras)
