// The carving box in an OctoMap file's header: written exact to the double, read back, a comment to
// OctoMap's own reader; files without it, malformed lines and files that are not OctoMaps.

#include <gtest/gtest.h>
#include <octomap/OcTree.h>

#include <fstream>
#include <limits>
#include <optional>
#include <string>

#include "common/test_data.h"
#include "sift_hull/hull/hull_octomap.h"

namespace sift_hull {
namespace {

octomap::OcTree smallTree() {
  octomap::OcTree tree(0.05);
  for (int i = 0; i < 20; ++i) tree.updateNode(0.05 * i, 0.1, -0.2, true);
  return tree;
}

std::string writeText(const std::string& name, const std::string& text) {
  const std::string path = test::temporaryDirectory() + "/" + name;
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

TEST(CarvingBoxFile, IsReadBackExactlyAndOctomapStillReadsTheFile) {
  const Box3d box{Eigen::Vector3d(-0.1 / 3.0, 1e-17, -2.5), Eigen::Vector3d(0.7, 1.0 / 7.0, 3e8)};
  const std::string path = test::temporaryDirectory() + "/boxed.bt";
  writeOctomap(smallTree(), path, box);
  const std::optional<Box3d> read = readCarvingBox(path);
  ASSERT_TRUE(read.has_value());
  EXPECT_EQ(read->min_W, box.min_W);  // to the bit
  EXPECT_EQ(read->max_W, box.max_W);
  EXPECT_EQ(boxText(*read), boxText(box));
  octomap::OcTree octomaps(0.1);
  ASSERT_TRUE(octomaps.readBinary(path)) << "OctoMap's reader must skip the line";
  EXPECT_EQ(octomaps.getNumLeafNodes(), smallTree().getNumLeafNodes());
  EXPECT_DOUBLE_EQ(octomaps.getResolution(), 0.05);
}

TEST(CarvingBoxFile, AFileWithoutTheLineHasNoBox) {
  const std::string path = test::temporaryDirectory() + "/plain.bt";
  writeOctomap(smallTree(), path);
  EXPECT_FALSE(readCarvingBox(path).has_value());
}

TEST(CarvingBoxFile, MalformedLinesAndOtherFilesAreRefusedWithTheLineNumber) {
  const std::string head = "# Octomap OcTree binary file\n# comment\n";
  for (const char* line :
       {"# carving_box 0,0,0,1,1", "# carving_box 0,0,0,1,1,1,1", "# carving_box 0,0,nan,1,1,1",
        "# carving_box 0;0;0;1;1;1", "# carving_box 2,0,0,1,1,1", "# carving_box 0,0,0,1,1,inf"}) {
    const std::string path = writeText("bad.bt", head + line + "\nid OcTree\ndata\n");
    try {
      readCarvingBox(path);
      ADD_FAILURE() << "accepted: " << line;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find("bad.bt:3:"), std::string::npos) << e.what();
    }
  }
  EXPECT_THROW(readCarvingBox(writeText("text.bt", "hello\n# carving_box 0,0,0,1,1,1\n")),
               std::runtime_error);
  EXPECT_THROW(readCarvingBox(test::temporaryDirectory() + "/missing.bt"), std::runtime_error);
  // A carving_box after "data" is binary data, not the header.
  EXPECT_FALSE(
      readCarvingBox(writeText("late.bt", head + "data\n# carving_box 0,0,0,1,1,1\n")).has_value());
}

}  // namespace
}  // namespace sift_hull
