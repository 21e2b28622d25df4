// The hull node's ~save: the files a requested path gives, and the paths it refuses.

#include <gtest/gtest.h>

#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

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

/// A new directory under TMPDIR (or /tmp), removed with what is in it.
struct TempDir {
  TempDir() {
    const char* base = std::getenv("TMPDIR");
    std::string pattern = std::string(base != nullptr ? base : "/tmp") + "/save_paths_XXXXXX";
    path = ::mkdtemp(&pattern[0]) != nullptr ? pattern : "";
  }
  ~TempDir() {
    if (!path.empty()) std::system(("rm -rf '" + path + "'").c_str());
  }
  std::string path;
};

std::string contents(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

TEST(SavePaths, RefuseAFifoADirectoryAndANulButNotARegularFile) {
  TempDir dir;
  ASSERT_FALSE(dir.path.empty());
  const std::string fifo = dir.path + "/hull.bt";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_THROW(checkRegularTarget(fifo), std::invalid_argument) << "opening it would block";
  EXPECT_THROW(checkRegularTarget(dir.path), std::invalid_argument);
  EXPECT_THROW(checkRegularTarget(std::string("/tmp/a\0b", 8)), std::invalid_argument);
  EXPECT_NO_THROW(checkRegularTarget(dir.path + "/new.ply")) << "a new file is fine";
  std::ofstream(dir.path + "/old.ply") << "old";
  EXPECT_NO_THROW(checkRegularTarget(dir.path + "/old.ply")) << "so is an existing one";
}

TEST(SavePaths, WriteReplacingLeavesTheOldFileUntilTheNewOneIsWhole) {
  TempDir dir;
  ASSERT_FALSE(dir.path.empty());
  const std::string path = dir.path + "/hull.ply";
  std::ofstream(path) << "old";
  EXPECT_THROW(writeReplacing(path,
                              [](const std::string& temporary) {
                                std::ofstream(temporary) << "half";
                                throw std::runtime_error("disk full");
                              }),
               std::runtime_error);
  EXPECT_EQ(contents(path), "old") << "a failed write leaves the old file";
  writeReplacing(path, [](const std::string& temporary) { std::ofstream(temporary) << "new"; });
  EXPECT_EQ(contents(path), "new");
  EXPECT_EQ(std::system(("test $(ls '" + dir.path + "' | wc -l) -eq 1").c_str()), 0)
      << "no temporary left beside it";
  struct stat info;
  ASSERT_EQ(::stat(path.c_str(), &info), 0);
  EXPECT_EQ(info.st_mode & 0777, 0644u) << "readable as an ordinary file";
  const std::string fifo = dir.path + "/fifo.bt";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_THROW(writeReplacing(fifo, [](const std::string&) {}), std::invalid_argument);
}

}  // namespace
}  // namespace sift_hull
