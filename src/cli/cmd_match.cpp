#include <algorithm>
#include <memory>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "args.h"
#include "commands.h"
#include "match_eval.h"
#include "match_options.h"
#include "match_table.h"
#include "sift_hull/draw/match_drawing.h"
#include "sift_hull/features/labelled_matches.h"
#include "sift_hull/filters/filter.h"
#include "sift_hull/filters/filter_result.h"
#include "sift_hull/filters/gsc.h"
#include "sift_hull/geometry/camera.h"
#include "sift_hull/io/calibration.h"
#include "sift_hull/io/images.h"
#include "sift_hull/pipeline/pair_pipeline.h"
#include "sift_hull/synthetic/scene.h"

namespace sift_hull {
namespace cli {
namespace {

std::string baseName(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

void writeImage(const std::string& path, const cv::Mat& image) {
  if (!cv::imwrite(path, image)) throw std::runtime_error(path + ": cannot write the image");
}

size_t viewIndex(const std::vector<CalibratedView>& views, const std::string& name,
                 const std::string& source) {
  for (size_t i = 0; i < views.size(); ++i) {
    if (views[i].name == name) return i;
  }
  throw std::runtime_error(source + ": no view named '" + name + "'");
}

void addPairOptions(ArgParser* parser) {
  parser->addOption("calib", "FILE",
                    "calibration of the pair (Middlebury par, projections, COLMAP model "
                    "directory, NeRF transforms.json, or LLFF poses_bounds.npy or IDR cameras.npz, "
                    "whose views are the images beside the left one)");
  parser->addOption("left-view", "NAME", "LEFT's name in --calib (default: its file name)");
  parser->addOption("right-view", "NAME", "RIGHT's name in --calib (default: its file name)");
  parser->addFlag("rectified", "the pair is rectified: epipolar lines are image rows");
  parser->addOption("gt-disparity", "FILE", "ground truth: the left image's disparity map");
  parser->addOption("disparity-scale", "S", "disparity = pixel value / S (Middlebury: 4)", "1");
  parser->addOption("gt-homography", "FILE", "ground truth: 3x3 H with x_right ~ H x_left");
  parser->addOption("gt-scene", "DIR", "ground truth: a scene directory (sift_hull scene)");
}

/// The camera of the view named `name` in `calib`, checked against its image: the size the
/// calibration gives (COLMAP's WIDTH x HEIGHT) and a lens distortion that does not fold over
/// within it, as the hull checks its views.
PinholeCamera checkedCamera(const std::vector<CalibratedView>& views, const std::string& name,
                            const std::string& calib, const cv::Mat& image,
                            const std::string& image_path) {
  const CalibratedView& view = views[viewIndex(views, name, calib)];
  checkImageSize(view, image.size(), image_path);
  try {
    requireUnfoldedDistortion(name, view.camera, image.cols, image.rows);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(calib + ": " + e.what());
  }
  return view.camera;
}

/// Calibrates the pair from --rectified, --calib or the scene's cameras, when any is given.
void calibrate(const ArgParser& parser, const std::string& left, const std::string& right,
               PairInput* input) {
  if (parser.flag("rectified")) {
    input->F_right_left = rectifiedFundamentalMatrix();
    return;
  }
  std::string calib;
  if (parser.has("calib")) {
    calib = parser.get("calib");
  } else if (parser.has("gt-scene")) {
    calib = sceneCalibration(parser.get("gt-scene"));
  } else {
    return;
  }
  const std::vector<CalibratedView> views = readCalibrationWithImages(calib, parentDirectory(left));
  const std::string left_name = parser.has("left-view") ? parser.get("left-view") : baseName(left);
  const std::string right_name =
      parser.has("right-view") ? parser.get("right-view") : baseName(right);
  // Left first: the order of a call's arguments is unspecified.
  const PinholeCamera left_camera = checkedCamera(views, left_name, calib, input->left_image, left);
  input->cameras = std::make_pair(
      left_camera, checkedCamera(views, right_name, calib, input->right_image, right));
}

/// Refuses a --gt-scene that is not the scene of the pair: each image must have the scene's size
/// and, with --calib, the calibration's cameras must be the scene's (requireViewsOfScene).
void checkSceneOfPair(const ArgParser& parser, const SceneData& scene,
                      const std::vector<std::string>& paths, const std::vector<cv::Mat>& images) {
  const std::string directory = parser.get("gt-scene");
  for (size_t i = 0; i < paths.size(); ++i) {
    if (images[i].cols != scene.config.width_px || images[i].rows != scene.config.height_px) {
      throw std::runtime_error("--gt-scene " + directory + " is not the scene of " + paths[i] +
                               ": its views are " + std::to_string(scene.config.width_px) + "x" +
                               std::to_string(scene.config.height_px) + ", the image is " +
                               std::to_string(images[i].cols) + "x" +
                               std::to_string(images[i].rows));
    }
  }
  if (!parser.has("calib")) return;
  const std::string calib = parser.get("calib");
  const std::vector<CalibratedView> views =
      readCalibrationWithImages(calib, parentDirectory(paths[0]));
  HullInput pair;  // names and cameras only
  pair.names = {parser.has("left-view") ? parser.get("left-view") : baseName(paths[0]),
                parser.has("right-view") ? parser.get("right-view") : baseName(paths[1])};
  for (const std::string& name : pair.names) {
    pair.cameras.push_back(views[viewIndex(views, name, calib)].camera);
  }
  requireViewsOfScene(scene, directory, pair, calib);
}

std::optional<PairTruth> pairTruth(const ArgParser& parser, const std::string& left,
                                   const std::string& right, const cv::Mat& left_image,
                                   const cv::Mat& right_image) {
  const int given =
      parser.has("gt-disparity") + parser.has("gt-homography") + parser.has("gt-scene");
  if (given > 1)
    throw UsageError("give at most one of --gt-disparity, --gt-homography, --gt-scene");
  if (parser.has("gt-disparity")) {
    const double scale = parser.getDouble("disparity-scale");
    if (!(scale > 0.0)) throw UsageError("--disparity-scale must be positive");
    return disparityTruth(parser.get("gt-disparity"), scale);
  }
  if (parser.has("gt-homography")) return homographyTruth(parser.get("gt-homography"));
  if (!parser.has("gt-scene")) return std::nullopt;
  const SceneData scene = readScene(parser.get("gt-scene"));
  const size_t a = viewIndex(scene.views, baseName(left), parser.get("gt-scene"));
  const size_t b = viewIndex(scene.views, baseName(right), parser.get("gt-scene"));
  checkSceneOfPair(parser, scene, {left, right}, {left_image, right_image});
  return sceneTruth({scene.views[a].camera, scene.depths[a]},
                    {scene.views[b].camera, scene.depths[b]});
}

/// Every filter the input allows (epipolar only when calibrated).
std::vector<std::string> applicableFilters(bool calibrated) {
  std::vector<std::string> names;
  for (const std::string& name : filterNames()) {
    if (name != "epipolar" || calibrated) names.push_back(name);
  }
  return names;
}

/// The filters named with --filter ("all": every one the input allows), else kDefaultFilter.
/// Throws UsageError for a name makeFilter refuses, and for epipolar without calibration.
std::vector<std::string> chosenFilters(const ArgParser& parser, bool calibrated) {
  std::vector<std::string> names = parser.getAll("filter");
  if (names.empty()) return {kDefaultFilter};
  if (std::find(names.begin(), names.end(), "all") != names.end()) {
    return applicableFilters(calibrated);
  }
  for (const std::string& name : names) {
    try {
      makeFilter(name, FilterConfigs());
    } catch (const std::invalid_argument& e) {
      throw UsageError(std::string("--filter: ") + e.what());
    }
    if (!calibrated && ("+" + name + "+").find("+epipolar+") != std::string::npos) {
      throw UsageError("--filter " + name +
                       ": epipolar needs calibration (--calib, --rectified or --gt-scene)");
    }
  }
  return names;
}

/// The result as text, the filters in the order they ran (`order`: the order given).
std::string describe(const nlohmann::json& result, const std::vector<std::string>& order) {
  std::ostringstream text;
  text << result["putative"] << " putative matches";
  if (result.contains("ground_truth")) {
    const auto& truth = result["ground_truth"];
    text << " (" << truth["correct"] << " correct, " << truth["wrong"] << " wrong, "
         << truth["unknown"] << " without ground truth)";
  }
  const nlohmann::json& ms = result["time_ms"];
  text << "\nSIFT " << ms["sift_left"] << " ms (left), " << ms["sift_right"]
       << " ms (right); matching " << ms["matching"] << " ms\n";
  for (const std::string& name : order) {
    const nlohmann::json& run = result["filters"][name];
    text << "  " << name << ": kept " << run["kept"] << " in " << run["time_ms"] << " ms";
    if (!run["precision"].is_null()) {
      text << ", precision " << run["precision"] << ", recall " << run["recall"] << ", F1 "
           << run["f1"] << ", mismatches removed " << run["mismatches_removed"];
    }
    text << "\n";
  }
  return text.str();
}

/// The kept match with the median GSC distance and the removed one with the median distance
/// (with ground truth: among the correct kept and the wrong removed ones).
void writeHistogramFigure(const std::string& path, const PutativeMatches& input,
                          const FilterConfigs& configs, const std::vector<MatchTruth>* truth) {
  const FilterResult gsc = filterGsc(input, configs.gsc);
  std::vector<std::pair<double, size_t>> kept, removed;
  for (size_t m = 0; m < input.matches.size(); ++m) {
    if (std::isnan(gsc.score[m])) continue;
    const MatchTruth expected = gsc.keep[m] ? MatchTruth::kCorrect : MatchTruth::kWrong;
    if (truth != nullptr && (*truth)[m] != expected) continue;
    (gsc.keep[m] ? kept : removed).emplace_back(gsc.score[m], m);
  }
  if (kept.empty() || removed.empty()) {
    throw std::runtime_error("--out-histograms: gsc kept or removed no match, nothing to draw");
  }
  std::sort(kept.begin(), kept.end());
  std::sort(removed.begin(), removed.end());
  const cv::Mat figure =
      drawGscHistograms(gscHistograms(input, kept[kept.size() / 2].second),
                        gscHistograms(input, removed[removed.size() / 2].second));
  writeImage(path, figure);
}

/// Each chosen filter once, in the order first given.
std::vector<std::unique_ptr<MatchFilter>> chosenFilterObjects(const ArgParser& parser,
                                                              const FilterConfigs& configs,
                                                              bool calibrated) {
  std::vector<std::unique_ptr<MatchFilter>> filters;
  for (const std::string& name : chosenFilters(parser, calibrated)) {
    std::unique_ptr<MatchFilter> filter = makeFilter(name, configs);
    const bool seen = std::any_of(filters.begin(), filters.end(), [&](const auto& other) {
      return other->name() == filter->name();
    });
    if (!seen) filters.push_back(std::move(filter));
  }
  return filters;
}

/// The pair through the core pipeline (runPair); fills result["filters"] and `order` (the
/// filters' names as run) and returns the runs.
std::vector<FilterRun> filterRuns(const PairResult& pair, const std::vector<MatchTruth>* truth,
                                  nlohmann::json* result, std::vector<std::string>* order) {
  for (const FilterVerdicts& run : pair.verdicts) {
    (*result)["filters"][run.name] = filterRunJson(run, truth);
    order->push_back(run.name);
  }
  return pair.verdicts;
}

nlohmann::json timesJson(const PairTimes& times) {
  return {{"sift_left", times.sift_left_ms},
          {"sift_right", times.sift_right_ms},
          {"matching", times.matching_ms}};
}

/// LEFT and RIGHT through the core pipeline (runPair), calibrated as the options say, with each
/// chosen filter.
PairResult runPairOfFiles(const ArgParser& parser, const MatchOptions& options, const cv::Mat& left,
                          const cv::Mat& right) {
  const std::string left_path = parser.get("LEFT"), right_path = parser.get("RIGHT");
  PairInput input;
  input.left_image = left, input.right_image = right;
  input.min_keypoints = 0;  // every pair filtered: an image without features keeps nothing
  calibrate(parser, left_path, right_path, &input);
  const bool calibrated = input.cameras || input.F_right_left;
  const auto filters = chosenFilterObjects(parser, options.filters, calibrated);
  const PairPipelineConfig pipeline{options.sift, options.matching, 0.0};
  return runPair(input, pipeline, filterPointers(filters));
}

void addMatchCommandOptions(ArgParser* parser) {
  parser->addPositional("LEFT", "left image");
  parser->addPositional("RIGHT", "right image");
  parser->addOption("filter", "NAME", "a filter to run (default best; all: every one); repeat");
  addMatchOptions(parser);
  addPairOptions(parser);
  parser->addOption("out-image", "PNG", "draw the first filter's kept (green) and removed (red)");
  parser->addOption("out-histograms", "PNG", "draw GSC histograms of a kept and a removed match");
  parser->addOption("out-matches", "FILE",
                    "one row per putative: points, sizes, angles, descriptor distance, each "
                    "filter's keep and score (.csv or .json)");
  parser->addFlag("json", "print the result as one JSON object");
}

}  // namespace

int runMatch(const std::vector<std::string>& args) {
  ArgParser parser("match",
                   "Matches SIFT features of two images and filters the putative matches with\n"
                   "each --filter (best, vote_ransac, guided, lsc, local_gsc, gsc, ratio,\n"
                   "epipolar, ransac, magsac, gms, a+b to keep what both keep, or all; default:\n"
                   "best), scoring them\n"
                   "against ground truth when one is given.");
  addMatchCommandOptions(&parser);
  if (!parser.parse(args)) return 0;
  const MatchOptions options = matchOptionsFromArgs(parser);
  if (parser.has("out-matches")) checkMatchTablePath(parser.get("out-matches"));
  const std::string left_path = parser.get("LEFT"), right_path = parser.get("RIGHT");
  const cv::Mat left = readImage(left_path), right = readImage(right_path);

  const std::optional<PairTruth> truth = pairTruth(parser, left_path, right_path, left, right);
  const PairResult pair = runPairOfFiles(parser, options, left, right);
  const PutativeMatches& input = pair.putative;
  const std::vector<MatchTruth> judged = truth ? truth->judge(input) : std::vector<MatchTruth>();
  const std::vector<MatchTruth>* truth_or_null = truth ? &judged : nullptr;

  nlohmann::json result = {{"putative", input.matches.size()},
                           {"left_keypoints", input.left_keypoints.size()},
                           {"right_keypoints", input.right_keypoints.size()},
                           {"time_ms", timesJson(pair.times)},
                           {"filters", nlohmann::json::object()}};
  if (truth) result["ground_truth"] = truthJson(truth->kind, judged);
  std::vector<std::string> order;
  const std::vector<FilterRun> runs = filterRuns(pair, truth_or_null, &result, &order);
  if (parser.has("out-image") && !runs.empty()) {
    writeImage(parser.get("out-image"), drawMatchDecisions(left, right, input, runs[0].result));
  }
  if (parser.has("out-matches")) {
    writeMatchTable(parser.get("out-matches"), input, runs, truth_or_null);
  }
  if (parser.has("out-histograms")) {
    writeHistogramFigure(parser.get("out-histograms"), input, options.filters, truth_or_null);
  }
  printResult(parser.flag("json"), result, describe(result, order));
  return 0;
}

}  // namespace cli
}  // namespace sift_hull
