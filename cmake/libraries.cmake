# sift_hull_add_libraries(ROOT <package root> [SUFFIX <suffix>] [STATIC])
#
# The four ROS-free libraries of the package, by layer (docs/ARCHITECTURE.md), each linking only
# the layers below it:
#   sift_hull_core<suffix>      geometry, features, filters, hull, refine
#   sift_hull_io<suffix>        file formats; links sift_hull_core
#   sift_hull_pipeline<suffix>  pair pipeline, matches refinement, drawing; links sift_hull_core
#   sift_hull_eval<suffix>      synthetic renderer and evaluation; links sift_hull_io and
#                               sift_hull_pipeline
# Used by the package's CMakeLists.txt and by the sanitizer build (test/sanitize), which makes static
# variants with other compile flags. Expects OpenCV, Eigen3, octomap, VTK, GLPK (GLPK_INCLUDE_DIR,
# GLPK_LIBRARY), OpenBLAS (OPENBLAS_INCLUDE_DIR, OPENBLAS_LIBRARY), nlohmann_json, minizip
# (PkgConfig::minizip) and Threads to be found already (cmake/dependencies.cmake).
include(${CMAKE_CURRENT_LIST_DIR}/sources.cmake)

function(sift_hull_add_libraries)
  cmake_parse_arguments(ARG "STATIC" "ROOT;SUFFIX" "" ${ARGN})
  set(type "")
  if(ARG_STATIC)
    set(type STATIC)
  endif()
  foreach(layer CORE IO PIPELINE EVAL EXACT_FLOAT)
    set(${layer} ${SIFT_HULL_${layer}_SOURCES})
    list(TRANSFORM ${layer} PREPEND "${ARG_ROOT}/")
  endforeach()
  set_source_files_properties(${EXACT_FLOAT} PROPERTIES COMPILE_OPTIONS "-ffp-contract=off")

  set(core sift_hull_core${ARG_SUFFIX})
  add_library(${core} ${type} ${CORE})
  target_include_directories(${core} PUBLIC
    $<BUILD_INTERFACE:${ARG_ROOT}/include> $<INSTALL_INTERFACE:include> ${OCTOMAP_INCLUDE_DIRS})
  target_include_directories(${core} PRIVATE ${ARG_ROOT}/src/core ${GLPK_INCLUDE_DIR}
    ${OPENBLAS_INCLUDE_DIR})
  target_link_libraries(${core} PUBLIC ${OpenCV_LIBS} Eigen3::Eigen ${OCTOMAP_LIBRARIES}
    Threads::Threads PRIVATE VTK::CommonCore VTK::CommonDataModel ${GLPK_LIBRARY}
    ${OPENBLAS_LIBRARY} SQLite::SQLite3)

  set(io sift_hull_io${ARG_SUFFIX})
  add_library(${io} ${type} ${IO})
  target_link_libraries(${io} PUBLIC ${core} PRIVATE nlohmann_json::nlohmann_json
    PkgConfig::minizip)

  set(pipeline sift_hull_pipeline${ARG_SUFFIX})
  add_library(${pipeline} ${type} ${PIPELINE})
  target_link_libraries(${pipeline} PUBLIC ${core})

  set(eval sift_hull_eval${ARG_SUFFIX})
  add_library(${eval} ${type} ${EVAL})
  target_include_directories(${eval} PRIVATE ${ARG_ROOT}/src/core)
  target_link_libraries(${eval} PUBLIC ${io} ${pipeline} PRIVATE nlohmann_json::nlohmann_json)
endfunction()
