// Every input of the fuzz corpus (test/fuzz/corpus/HARNESS/: the seeds and the regress_* inputs
// of fixed findings) replayed through its libFuzzer harness in the ordinary build, so that
// scripts/test.sh checks on every run that no input that once crashed a reader or the
// bounding-box solver crashes, aborts or hangs it again. The harnesses themselves (test/fuzz/)
// are compiled here with their entry point renamed (CMakeLists.txt).

#include <dirent.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <fstream>
#include <string>
#include <vector>

extern "C" int fuzz_middlebury_par(const uint8_t* data, size_t size);
extern "C" int fuzz_projection_list(const uint8_t* data, size_t size);
extern "C" int fuzz_homography(const uint8_t* data, size_t size);
extern "C" int fuzz_pfm(const uint8_t* data, size_t size);
extern "C" int fuzz_ply(const uint8_t* data, size_t size);
extern "C" int fuzz_bounding_box(const uint8_t* data, size_t size);
extern "C" int fuzz_colmap_binary(const uint8_t* data, size_t size);
extern "C" int fuzz_npy(const uint8_t* data, size_t size);
extern "C" int fuzz_nerf_transforms(const uint8_t* data, size_t size);
extern "C" int fuzz_idr_cameras(const uint8_t* data, size_t size);

namespace sift_hull {
namespace {

using Harness = int (*)(const uint8_t*, size_t);

std::vector<std::string> corpusFiles(const std::string& harness) {
  const std::string directory = std::string(SIFT_HULL_SOURCE_DIR) + "/test/fuzz/corpus/" + harness;
  std::vector<std::string> files;
  if (DIR* dir = opendir(directory.c_str())) {
    while (const dirent* entry = readdir(dir)) {
      if (entry->d_name[0] != '.') files.push_back(directory + "/" + entry->d_name);
    }
    closedir(dir);
  }
  std::sort(files.begin(), files.end());
  return files;
}

/// Runs every corpus file of `harness` once; a crash, abort or sanitizer report ends the test.
void replay(const std::string& harness, Harness run) {
  const std::vector<std::string> files = corpusFiles(harness);
  ASSERT_FALSE(files.empty()) << "no corpus for " << harness;
  for (const std::string& path : files) {
    std::ifstream in(path, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), {});
    SCOPED_TRACE(path);
    EXPECT_EQ(run(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size()), 0);
  }
}

TEST(FuzzCorpus, MiddleburyPar) { replay("fuzz_middlebury_par", fuzz_middlebury_par); }
TEST(FuzzCorpus, ProjectionList) { replay("fuzz_projection_list", fuzz_projection_list); }
TEST(FuzzCorpus, Homography) { replay("fuzz_homography", fuzz_homography); }
TEST(FuzzCorpus, Pfm) { replay("fuzz_pfm", fuzz_pfm); }
TEST(FuzzCorpus, Ply) { replay("fuzz_ply", fuzz_ply); }
TEST(FuzzCorpus, BoundingBox) { replay("fuzz_bounding_box", fuzz_bounding_box); }
TEST(FuzzCorpus, ColmapBinary) { replay("fuzz_colmap_binary", fuzz_colmap_binary); }
TEST(FuzzCorpus, Npy) { replay("fuzz_npy", fuzz_npy); }
TEST(FuzzCorpus, NerfTransforms) { replay("fuzz_nerf_transforms", fuzz_nerf_transforms); }
TEST(FuzzCorpus, IdrCameras) { replay("fuzz_idr_cameras", fuzz_idr_cameras); }

}  // namespace
}  // namespace sift_hull
