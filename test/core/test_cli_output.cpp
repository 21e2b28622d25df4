// What the programs print: the command lists of sift_hull and sift_hull_bench, which name each
// other's commands, the filters in the order given, and nothing but the JSON with --json.

#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "common/test_data.h"

namespace sift_hull {
namespace {

std::string fileText(const std::string& path) {
  std::ifstream in(path);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

using CommandOutput = test::WrittenSceneSuite;

/// The commands a program's --help lists (lines of two spaces, a name and its summary), each
/// summary checked to start in one column, at least two spaces after its name.
std::vector<std::string> listedCommands(const std::string& help) {
  std::istringstream lines(help);
  std::string line;
  std::vector<std::string> names;
  size_t summary_column = 0;
  while (std::getline(lines, line)) {
    if (line.rfind("  ", 0) != 0) continue;  // a command: two spaces, its name, its summary
    const size_t name_end = line.find(' ', 2);
    const size_t summary = line.find_first_not_of(' ', name_end);
    EXPECT_NE(summary, std::string::npos) << line;
    if (summary == std::string::npos) continue;
    EXPECT_GE(summary - name_end, 2u) << "name and summary run together: " << line;
    if (names.empty()) summary_column = summary;
    EXPECT_EQ(summary, summary_column) << "summaries in one column: " << line;
    names.push_back(line.substr(2, name_end - 2));
  }
  return names;
}

/// The commands that `help` names for the program `other`: the list in parentheses of its line
/// "- OTHER: summary (a, b, c)".
std::vector<std::string> commandsNamedFor(const std::string& help, const std::string& other) {
  const size_t line = help.find("\n- " + other + ": ");
  if (line == std::string::npos) return {};
  const size_t open = help.find('(', line), close = help.find(")\n", line);
  std::vector<std::string> names;
  std::istringstream list(help.substr(open + 1, close - open - 1));
  for (std::string name; std::getline(list, name, ',');)
    names.push_back(name.substr(name[0] == ' '));
  return names;
}

TEST(ProgramHelp, KeepsEveryCommandApartFromItsSummary) {
  std::string out, err;
  ASSERT_EQ(test::runProgram("--help", &out, &err), 0) << err;
  EXPECT_EQ(listedCommands(out),
            (std::vector<std::string>{"dataset-info", "scene", "match", "hull"}))
      << out;
  ASSERT_EQ(test::runBenchProgram("--help", &out, &err), 0) << err;
  EXPECT_EQ(listedCommands(out).size(), 4u) << out;
  EXPECT_NE(out.find("evaluate-filters  "), std::string::npos) << out;
}

TEST(ProgramHelp, NamesTheOtherProgramsWithTheCommandsTheyHave) {
  std::string user, bench, err;
  ASSERT_EQ(test::runProgram("--help", &user, &err), 0) << err;
  ASSERT_EQ(test::runBenchProgram("--help", &bench, &err), 0) << err;
  EXPECT_EQ(commandsNamedFor(user, "sift_hull_bench"), listedCommands(bench)) << user;
  EXPECT_EQ(commandsNamedFor(bench, "sift_hull"), listedCommands(user)) << bench;
  EXPECT_EQ(commandsNamedFor(user, "sift_hull_ros"), commandsNamedFor(bench, "sift_hull_ros"));
  EXPECT_FALSE(commandsNamedFor(user, "sift_hull_ros").empty()) << user;
}

TEST_F(CommandOutput, ListsTheFiltersInTheOrderGiven) {
  const std::string pair = *scene_ + "/view_0000.png " + *scene_ + "/view_0001.png";
  std::string out, err;
  ASSERT_EQ(
      test::runProgram("match " + pair + " --filter ransac --filter gsc --filter gms", &out, &err),
      0)
      << err;
  const size_t ransac = out.find("  ransac:"), gsc = out.find("  gsc:"), gms = out.find("  gms:");
  ASSERT_NE(ransac, std::string::npos) << out;
  ASSERT_NE(gsc, std::string::npos) << out;
  ASSERT_NE(gms, std::string::npos) << out;
  EXPECT_LT(ransac, gsc) << out;
  EXPECT_LT(gsc, gms) << out;
}

TEST_F(CommandOutput, MatchRunsBestByDefaultAndTimesSiftAndMatching) {
  const std::string pair = *scene_ + "/view_0000.png " + *scene_ + "/view_0001.png";
  std::string out, err;
  ASSERT_EQ(test::runProgram("match " + pair + " --json", &out, &err), 0) << err;
  const nlohmann::json result = nlohmann::json::parse(out);
  ASSERT_EQ(result["filters"].size(), 1u) << out;
  EXPECT_TRUE(result["filters"].contains("best")) << out;
  for (const char* key : {"sift_left", "sift_right", "matching"})
    EXPECT_GT(result["time_ms"][key].get<double>(), 0.0) << key;
  ASSERT_EQ(test::runProgram("match " + pair + " --json --filter all", &out, &err), 0) << err;
  EXPECT_GE(nlohmann::json::parse(out)["filters"].size(), 9u) << "every filter but epipolar";
}

TEST_F(CommandOutput, WritesOneRowPerPutativeAsCsvAndJson) {
  const std::string pair = *scene_ + "/view_0000.png " + *scene_ + "/view_0001.png";
  const std::string dir = test::temporaryDirectory();
  std::string out, err;
  ASSERT_EQ(test::runProgram("match " + pair + " --gt-scene " + *scene_ + " --json --filter gsc " +
                                 "--filter best --out-matches " + dir + "/m.csv",
                             &out, &err),
            0)
      << err;
  const nlohmann::json result = nlohmann::json::parse(out);
  std::istringstream csv(fileText(dir + "/m.csv"));
  std::string header, line;
  std::getline(csv, header);
  EXPECT_EQ(header,
            "match,left_x,left_y,left_size,left_angle,right_x,right_y,right_size,right_angle,"
            "descriptor_distance,truth,gsc_keep,gsc_score,best_keep,best_score");
  size_t rows = 0, kept = 0;
  while (std::getline(csv, line)) {
    ++rows;
    kept += line.find(",correct,") != std::string::npos ||
            line.find(",wrong,") != std::string::npos ||
            line.find(",unknown,") != std::string::npos;
  }
  EXPECT_EQ(rows, result["putative"].get<size_t>());
  EXPECT_EQ(kept, rows) << "every row carries its truth";
  ASSERT_EQ(test::runProgram("match " + pair + " --out-matches " + dir + "/m.json", &out, &err), 0);
  const nlohmann::json table = nlohmann::json::parse(fileText(dir + "/m.json"));
  ASSERT_EQ(table.size(), rows);
  size_t best_kept = 0;
  for (const auto& row : table) best_kept += row["best_keep"].get<int>();
  EXPECT_GT(best_kept, rows / 2);
  EXPECT_TRUE(table[0].contains("descriptor_distance"));
  EXPECT_EQ(test::runProgram("match " + pair + " --out-matches " + dir + "/m.txt", &out, &err), 2);
  EXPECT_NE(err.find("must end in .csv or .json"), std::string::npos) << err;
}

TEST_F(CommandOutput, PrintsOnlyJsonWithJson) {
  const std::string dir = test::temporaryDirectory();
  std::string out, err;
  ASSERT_EQ(test::runProgram("hull --calib " + *scene_ + "/scene_par.txt --images " + *scene_ +
                                 " --silhouettes " + *scene_ +
                                 "/masks --max-depth 5 --out-octree " + dir + "/hull.bt --json",
                             &out, &err),
            0)
      << err;
  EXPECT_EQ(err, "") << "stderr of a clean --json run";
  EXPECT_TRUE(nlohmann::json::accept(out)) << out;
}

TEST_F(CommandOutput, TakesTheBoxFromAnOctreeItWrote) {
  const std::string dir = test::temporaryDirectory();
  const std::string hull = "hull --calib " + *scene_ + "/scene_par.txt --images " + *scene_ +
                           " --silhouettes " + *scene_ + "/masks --max-depth 5 --json";
  std::string out, err;
  // A box other than the LP's, so that taking it back is seen.
  ASSERT_EQ(test::runProgram(hull + " --box -1.1,-1.2,-1.3,1.4,1.5,1.6 --out-octree " + dir +
                                 "/first.bt",
                             &out, &err),
            0)
      << err;
  const nlohmann::json first = nlohmann::json::parse(out);
  ASSERT_EQ(test::runProgram(hull + " --box " + dir + "/first.bt", &out, &err), 0) << err;
  const nlohmann::json second = nlohmann::json::parse(out);
  EXPECT_EQ(second["bbox"], first["bbox"]);
  EXPECT_EQ(second["bbox"]["min"][0].get<double>(), -1.1);
  EXPECT_EQ(second["occupied_leaves"], first["occupied_leaves"]);
  // A file without the line, or none at all: bad input (1), named.
  std::ofstream(dir + "/plain.bt") << "# Octomap OcTree binary file\nid OcTree\ndata\n";
  EXPECT_EQ(test::runProgram(hull + " --box " + dir + "/plain.bt", &out, &err), 1);
  EXPECT_NE(err.find("has no carving_box line"), std::string::npos) << err;
  EXPECT_EQ(test::runProgram(hull + " --box " + dir + "/none.bt", &out, &err), 1);
  EXPECT_NE(err.find("none.bt: cannot read the file"), std::string::npos) << err;
}

TEST_F(CommandOutput, TakesTheResolutionInMetresInsteadOfTheDepth) {
  const std::string hull = "hull --calib " + *scene_ + "/scene_par.txt --images " + *scene_ +
                           " --silhouettes " + *scene_ + "/masks --json --resolution-m ";
  std::string out, err;
  ASSERT_EQ(test::runProgram(hull + "0.05", &out, &err), 0) << err;
  const nlohmann::json result = nlohmann::json::parse(out);
  EXPECT_EQ(result["resolution_m"].get<double>(), 0.05);
  EXPECT_EQ(result["max_depth"].get<int>(), 6);  // a box of about 2 m: 2^6 - 3 cells of 5 cm
  EXPECT_EQ(test::runProgram(hull + "-1", &out, &err), 2);
  EXPECT_NE(err.find("--resolution-m must be a finite number >= 0, not -1"), std::string::npos)
      << err;
  EXPECT_EQ(test::runProgram(hull + "0.00001", &out, &err), 1);
  EXPECT_NE(err.find("raise resolution_m (at least"), std::string::npos) << err;
}

}  // namespace
}  // namespace sift_hull
