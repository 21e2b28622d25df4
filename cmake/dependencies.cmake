# The ROS-free dependencies of the package's libraries (cmake/libraries.cmake), found once here for
# both builds: the package's CMakeLists.txt and the sanitizer build (test/sanitize). All are
# Debian packages (scripts/apt-packages.txt).
find_package(OpenCV 4 REQUIRED COMPONENTS core imgproc imgcodecs features2d flann calib3d)
find_package(Eigen3 3.3 REQUIRED NO_MODULE)
find_package(nlohmann_json 3 REQUIRED)
find_package(octomap 1.9 REQUIRED)
find_package(VTK 9 REQUIRED COMPONENTS CommonCore CommonDataModel)
find_package(Threads REQUIRED)
# Debian's libglpk-dev ships no CMake or pkg-config file.
find_path(GLPK_INCLUDE_DIR glpk.h REQUIRED)
find_library(GLPK_LIBRARY glpk REQUIRED)
# OpenBLAS's cblas_sgemm for exact nearest neighbours (libopenblas-dev: the header of the variant
# that the alternatives system points at, and the library itself).
find_path(OPENBLAS_INCLUDE_DIR cblas.h PATH_SUFFIXES openblas-pthread openblas REQUIRED)
find_library(OPENBLAS_LIBRARY openblas REQUIRED)
# minizip (libminizip-dev) reads and writes the zip archives of numpy's .npz files (IDR cameras);
# Debian ships a pkg-config file for it, no CMake one.
find_package(PkgConfig REQUIRED)
pkg_check_modules(minizip REQUIRED IMPORTED_TARGET minizip)
# SQLite (libsqlite3-dev): the colmap filter reads the database COLMAP writes.
find_package(SQLite3 REQUIRED)
