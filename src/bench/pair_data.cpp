#include "pair_data.h"

#include <sys/stat.h>

#include <cstdlib>

#include "sift_hull/eval/match_evaluation.h"

namespace sift_hull {
namespace cli {
namespace {

bool exists(const std::string& path) {
  struct stat info;
  return stat(path.c_str(), &info) == 0;
}

/// The directory of a data set, or empty (with the reason) when it is absent.
std::string dataSet(const std::string& root, const std::string& name, std::string* why_not) {
  const std::string path = root + "/" + name;
  if (!root.empty() && exists(path)) return path;
  *why_not = "data set '" + name + "' not found (set SIFT_HULL_DATA or use --data)";
  return "";
}

}  // namespace

std::string defaultDataRoot() {
  if (const char* env = std::getenv("SIFT_HULL_DATA")) return env;
  return exists("../shared/data") ? "../shared/data" : "";
}

std::optional<EvaluationPair> teddyPair(const std::string& data_root, const MatchOptions& options,
                                        std::string* why_not) {
  const std::string dir = dataSet(data_root, "middlebury_stereo2003_teddy", why_not);
  if (dir.empty()) return std::nullopt;
  // Middlebury 2003 quarter size: im2 left, im6 right, disp2.pgm holds disparity * 4.
  return EvaluationPair{
      "teddy", matchRectifiedPair(dir + "/im2.png", dir + "/im6.png", dir + "/disp2.pgm", 4.0,
                                  options.sift, options.matching)};
}

std::optional<EvaluationPair> grafPair(const std::string& data_root, int n,
                                       const MatchOptions& options, std::string* why_not) {
  const std::string dir = dataSet(data_root, "oxford_affine_graf", why_not);
  if (dir.empty()) return std::nullopt;
  // Oxford's files: img1 .. img6, H1toNp maps img1 to imgN.
  const std::string index = std::to_string(n);
  return EvaluationPair{
      "graf 1-" + index,
      matchPlanarPair(dir + "/img1.png", dir + "/img" + index + ".png", dir + "/H1to" + index + "p",
                      options.sift, options.matching)};
}

}  // namespace cli
}  // namespace sift_hull
