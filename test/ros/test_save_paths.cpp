// The hull node's ~save: the files a requested path gives, and the paths it refuses.

#include <gtest/gtest.h>

#include <stdexcept>

#include "lib/save_paths.h"

namespace sift_hull {
namespace {

TEST(SavePaths, AddBothExtensionsToAStem) {
  const SavePaths paths = savePaths("/tmp/hull");
  EXPECT_EQ(paths.octree, "/tmp/hull.bt");
  EXPECT_EQ(paths.mesh, "/tmp/hull.ply");
}

TEST(SavePaths, KeepAGivenExtension) {
  EXPECT_EQ(savePaths("x.bt").octree, "x.bt");
  EXPECT_EQ(savePaths("x.bt").mesh, "x.ply");
  EXPECT_EQ(savePaths("out/x.ply").mesh, "out/x.ply");
  EXPECT_EQ(savePaths("out/x.ply").octree, "out/x.bt");
  EXPECT_EQ(savePaths("x.v2").octree, "x.v2.bt") << "another extension is part of the stem";
}

TEST(SavePaths, RefuseAPathThatNamesNoFile) {
  for (const char* path : {"", "/tmp/", ".bt", "dir/.ply", "/"}) {
    EXPECT_THROW(savePaths(path), std::invalid_argument) << "'" << path << "'";
  }
}

}  // namespace
}  // namespace sift_hull
