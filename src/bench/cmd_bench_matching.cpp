// bench-matching: SIFT and the descriptor matchers (OpenCV's brute force and FLANN, the matrix
// product's exact nearest neighbours) side by side at 1k, 4k and 8k keypoints per image.

#include <algorithm>
#include <opencv2/features2d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <thread>

#include "args.h"
#include "bench_commands.h"
#include "bench_measure.h"
#include "bench_report.h"
#include "commands.h"
#include "pair_data.h"
#include "sift_hull/features/nearest_neighbours.h"
#include "sift_hull/features/sift.h"
#include "sift_hull/synthetic/scene.h"

namespace sift_hull {
namespace cli {
namespace {

/// The pair whose keypoints are matched: graf 1 and 3 at 1.5x (1200x960, enough keypoints for
/// 8,000 of each), else two views of the synthetic scene at 1280x960.
struct BenchPair {
  cv::Mat left, right;
  std::string name;
};

BenchPair benchPair(const std::string& data_root) {
  const std::string graf = data_root + "/oxford_affine_graf";
  BenchPair pair{cv::imread(graf + "/img1.png"), cv::imread(graf + "/img3.png"),
                 "graf img1 and img3 at 1.5x (1200x960)"};
  if (!data_root.empty() && !pair.left.empty() && !pair.right.empty()) {
    cv::resize(pair.left, pair.left, {}, 1.5, 1.5, cv::INTER_CUBIC);
    cv::resize(pair.right, pair.right, {}, 1.5, 1.5, cv::INTER_CUBIC);
    return pair;
  }
  SceneConfig scene;
  scene.width_px = 1280, scene.height_px = 960;
  return {renderSceneView(scene, 0).image, renderSceneView(scene, 1).image,
          "synthetic scene, views 0 and 1 at 1280x960 (graf not found under '" + data_root + "')"};
}

/// SIFT keeping the strongest `keypoints` (a low contrast threshold so that there are enough).
SiftConfig siftFor(int keypoints) {
  SiftConfig sift;
  sift.max_features = keypoints;
  sift.contrast_threshold = 0.01;
  return sift;
}

/// Share of queries whose nearest neighbour the exact matcher and BFMatcher agree on.
double sameNearestShare(const std::vector<std::vector<cv::DMatch>>& bf,
                        const NearestNeighbours& exact) {
  size_t same = 0;
  for (size_t i = 0; i < bf.size(); ++i)
    same += !bf[i].empty() && bf[i][0].trainIdx == exact.forward[i].best;
  return bf.empty() ? 1.0 : double(same) / bf.size();
}

nlohmann::json sizeRow(const BenchPair& pair, int keypoints) {
  const SiftConfig sift = siftFor(keypoints);
  Features left, right;
  const double sift_ms = medianMs([&] { left = detectSift(pair.left, sift); }, 2000.0);
  right = detectSift(pair.right, sift);
  std::vector<std::vector<cv::DMatch>> bf, flann;
  const auto bf_matcher = cv::BFMatcher::create(cv::NORM_L2);
  const auto flann_matcher = cv::FlannBasedMatcher::create();
  NearestNeighbours exact;
  nlohmann::json row = {{"requested", keypoints},
                        {"keypoints", {left.keypoints.size(), right.keypoints.size()}},
                        {"sift_ms_per_image", sift_ms}};
  row["opencv_bf_ms"] = medianMs(
      [&] {
        bf.clear();  // knnMatch appends
        bf_matcher->knnMatch(left.descriptors, right.descriptors, bf, 2);
      },
      3000.0);
  row["flann_ms"] = medianMs(
      [&] {
        flann.clear();
        flann_matcher->knnMatch(left.descriptors, right.descriptors, flann, 2);
      },
      3000.0);
  row["blas_ms"] = medianMs(
      [&] { exact = exactNearestNeighbours(left.descriptors, right.descriptors, false); }, 3000.0);
  row["blas_with_mutual_check_ms"] = medianMs(
      [&] { exact = exactNearestNeighbours(left.descriptors, right.descriptors, true); }, 3000.0);
  row["blas_kernel"] = exactNearestNeighboursKernel(left.descriptors, right.descriptors);
  NearestNeighbours float32;
  row["blas_float32_ms"] = medianMs(
      [&] { float32 = float32NearestNeighbours(left.descriptors, right.descriptors, false); },
      3000.0);
  row["speedup_vs_opencv_bf"] = row["opencv_bf_ms"].get<double>() / row["blas_ms"].get<double>();
  row["same_nearest_as_opencv_bf"] = sameNearestShare(bf, exact);
  row["float32_same_nearest_as_opencv_bf"] = sameNearestShare(bf, float32);
  return row;
}

std::string markdown(const nlohmann::json& result) {
  std::ostringstream md;
  md << "Written by `sift_hull_bench bench-matching --write docs/BENCHMARKS.md` on " << todayUtc()
     << ", CPU " << result["cpu"].get<std::string>() << " (/proc/cpuinfo), "
     << result["hardware_threads"] << " hardware threads, on " << result["pair"].get<std::string>()
     << ". Medians of repeated runs; every matcher finds the two nearest neighbours of each left "
        "descriptor among the right ones (k = 2), on all threads. `blas` ran its "
     << result["sizes"].back()["blas_kernel"].get<std::string>()
     << " kernel; the column `blas float32` is its float32 kernel "
        "(`float32NearestNeighbours`) on the same descriptors.\n\n"
        "| keypoints (left, right) | SIFT per image | OpenCV BFMatcher | FLANN | blas | blas + "
        "mutual check | blas float32 | speedup vs BFMatcher | same nearest as BFMatcher |\n"
        "| --- | --- | --- | --- | --- | --- | --- | --- | --- |\n";
  for (const auto& row : result["sizes"]) {
    md << "| " << row["keypoints"][0] << ", " << row["keypoints"][1] << " | "
       << fixed(row["sift_ms_per_image"], 1) << " ms | " << fixed(row["opencv_bf_ms"], 1)
       << " ms | " << fixed(row["flann_ms"], 1) << " ms | " << fixed(row["blas_ms"], 1) << " ms | "
       << fixed(row["blas_with_mutual_check_ms"], 1) << " ms | " << fixed(row["blas_float32_ms"], 1)
       << " ms | " << fixed(row["speedup_vs_opencv_bf"], 1) << "x | "
       << fixed(100.0 * row["same_nearest_as_opencv_bf"].get<double>(), 2) << " % |\n";
  }
  md << '\n' << measurementsMarkdown(result["measurements"]);
  return md.str();
}

}  // namespace

int runBenchMatching(const std::vector<std::string>& args) {
  ArgParser parser("bench-matching",
                   "Times SIFT and the descriptor matchers (OpenCV's BFMatcher and FLANN, the\n"
                   "exact matrix-product matcher 'blas') at 1k, 4k and 8k keypoints per image.");
  parser.addOption("data", "DIR", "real data root (graf)", defaultDataRoot());
  parser.addOption("write", "FILE", "replace the bench-matching section of this Markdown file");
  parser.addFlag("json", "print the result as one JSON object");
  if (!parser.parse(args)) return 0;
  const BenchPair pair = benchPair(parser.has("data") ? parser.get("data") : "");
  nlohmann::json result = {{"cpu", cpuModel()},
                           {"hardware_threads", std::thread::hardware_concurrency()},
                           {"pair", pair.name},
                           {"sizes", nlohmann::json::array()}};
  for (int keypoints : {1000, 4000, 8000}) result["sizes"].push_back(sizeRow(pair, keypoints));
  const double speedup = result["sizes"].back()["speedup_vs_opencv_bf"];
  result["speedup_vs_opencv_bf"] = speedup;
  // What the target of docs/BENCHMARKS.md is judged on.
  result["measurements"] = {{"speedup_vs_opencv_bf_8000", speedup}};
  const std::string text = markdown(result);
  if (parser.has("write")) replaceMarkedSection(parser.get("write"), "bench-matching", text);
  printResult(parser.flag("json"), result, text);
  return 0;
}

}  // namespace cli
}  // namespace sift_hull
