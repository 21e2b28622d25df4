// The default silhouette method, "auto": how well silhouettes agree across views
// (silhouetteAgreement), and the choice between the background and views methods it makes.
#include <gtest/gtest.h>

#include <iostream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "common/test_data.h"
#include "sift_hull/hull/view_silhouette_set.h"
#include "sift_hull/hull/view_silhouettes.h"
#include "sift_hull/io/images.h"
#include "sift_hull/synthetic/scene.h"

namespace sift_hull {
namespace {

SceneConfig scene(const std::string& background, const std::string& support) {
  SceneConfig config;
  config.views = 12;
  config.layout = "sphere";
  config.width_px = 320;
  config.height_px = 240;
  config.background = background;
  config.support = support;
  return config;
}

double iou(const cv::Mat& a, const cv::Mat& b) {
  const double both = cv::countNonZero(a & b), either = cv::countNonZero(a | b);
  return either > 0.0 ? both / either : 1.0;
}

TEST(SilhouetteChoice, AgreementFallsWhenViewsTakeBackgroundOrLoseTheObject) {
  const std::vector<RenderedView> rendered = renderScene(scene("black", "none"));
  std::vector<cv::Mat> masks;
  std::vector<PinholeCamera> cameras;
  std::vector<std::string> names;
  for (const RenderedView& view : rendered) {
    masks.push_back(view.mask.clone());
    cameras.push_back(view.view.camera);
    names.push_back(view.view.name);
  }
  const double exact = silhouetteAgreement(masks, cameras, names, 400);
  // Three views take a patch of background joined to the object (a shadow, a patch of table);
  // one loses its lower third (a dark part taken for the background).
  for (const size_t v : {1u, 5u, 9u}) {
    const cv::Rect box = cv::boundingRect(masks[v]);
    cv::rectangle(masks[v], cv::Rect(box.x - 30, box.br().y - 20, box.width + 60, 40),
                  cv::Scalar(255), cv::FILLED);
  }
  const cv::Rect box = cv::boundingRect(masks[3]);
  masks[3](cv::Rect(0, box.y + 2 * box.height / 3, masks[3].cols, box.height / 3 + 1)).setTo(0);
  const double spoilt = silhouetteAgreement(masks, cameras, names, 400);
  std::cout << "agreement: exact masks " << exact << ", spoilt " << spoilt << '\n';
  EXPECT_GT(exact, 0.93);
  EXPECT_LT(spoilt, exact - 0.1);  // measured 0.935 and 0.763
  EXPECT_THROW(silhouetteAgreement({masks[0]}, {cameras[0]}, {names[0]}, 400),
               std::invalid_argument);
}

/// The scene's images written to a temporary directory and read back with the "auto" method.
struct Chosen {
  std::vector<RenderedView> truth;
  std::vector<cv::Mat> masks;
  ViewSilhouettes report;
  double mean_iou = 0.0;
};
Chosen chooseOn(const SceneConfig& config) {
  Chosen chosen;
  const std::string dir = test::temporaryDirectory();
  chosen.truth = renderScene(config);
  std::vector<CalibratedView> views;
  for (const RenderedView& view : chosen.truth) {
    cv::imwrite(dir + "/" + view.view.name, view.image);
    views.push_back(view.view);
  }
  SilhouetteConfig method;
  EXPECT_EQ(method.silhouette_method, "auto") << "the default";
  chosen.masks = loadSilhouettes(views, dir, "", method, &chosen.report);
  for (size_t i = 0; i < views.size(); ++i) {
    chosen.mean_iou += iou(chosen.masks[i], chosen.truth[i].mask) / views.size();
  }
  std::cout << config.background << " background, support " << config.support << ": "
            << chosen.report.method << " (agreement views " << chosen.report.agreement
            << ", background " << chosen.report.background_agreement << "), mask IoU "
            << chosen.mean_iou << '\n';
  return chosen;
}

TEST(SilhouetteChoice, PlainBackgroundKeepsThePerImageColourModel) {
  const Chosen chosen = chooseOn(scene("black", "none"));
  EXPECT_EQ(chosen.report.method, "background");
  EXPECT_GE(chosen.report.background_agreement, chosen.report.agreement - 0.01);
  for (size_t i = 0; i < chosen.truth.size(); ++i) {
    SilhouetteConfig background;
    background.silhouette_method = "background";
    const cv::Mat expected = silhouetteFromImage(chosen.truth[i].image, background);
    EXPECT_EQ(cv::countNonZero(chosen.masks[i] != expected), 0) << chosen.truth[i].view.name;
  }
  EXPECT_GT(chosen.mean_iou, 0.98);
}

TEST(SilhouetteChoice, FloorWithShadowsTakesTheViewsMethod) {
  const Chosen chosen = chooseOn(scene("textured", "floor"));
  EXPECT_EQ(chosen.report.method, "views");
  EXPECT_LT(chosen.report.background_agreement, 0.0);
  EXPECT_NE(chosen.report.background_reason.find("textured"), std::string::npos);
  EXPECT_GT(chosen.mean_iou, 0.95);
}

TEST(SilhouetteChoice, WhereTheViewsMethodFailsEachViewKeepsItsOwnSilhouette) {
  // Two views of a ring of 36, 40 degrees apart: their frusta share no bounded part, their
  // silhouettes do.
  SceneConfig config = scene("black", "none");
  config.layout = "ring";
  config.views = 36;
  const std::string dir = test::temporaryDirectory();
  std::vector<RenderedView> truth;
  std::vector<CalibratedView> views;
  for (const int v : {0, 4}) {
    truth.push_back(renderSceneView(config, v));
    cv::imwrite(dir + "/" + truth.back().view.name, truth.back().image);
    views.push_back(truth.back().view);
  }
  ViewSilhouettes report;
  const std::vector<cv::Mat> masks = loadSilhouettes(views, dir, "", SilhouetteConfig(), &report);
  EXPECT_EQ(report.method, "background");
  EXPECT_NE(report.background_reason.find("the views method failed"), std::string::npos)
      << report.background_reason;
  ASSERT_EQ(report.warnings.size(), 1u);
  SilhouetteConfig background;
  background.silhouette_method = "background";
  for (size_t i = 0; i < truth.size(); ++i) {
    EXPECT_EQ(cv::countNonZero(masks[i] != silhouetteFromImage(truth[i].image, background)), 0);
  }
  // Named, the views method fails as before.
  SilhouetteConfig views_method;
  views_method.silhouette_method = "views";
  EXPECT_THROW(loadSilhouettes(views, dir, "", views_method), std::runtime_error);
}

TEST(SilhouetteChoice, ViewsArrivingOneAtATimeAreSegmentedTogetherAsTheSetGrows) {
  const std::vector<RenderedView> rendered = renderScene(scene("textured", "floor"));
  ViewSilhouetteSet set(SilhouetteConfig(), 200);
  std::vector<size_t> due_at;
  ViewSilhouetteSet::Segmented last;
  double per_image = 0.0;
  for (size_t v = 0; v < rendered.size(); ++v) {
    const cv::Mat now = set.add(rendered[v].view.name, rendered[v].image, rendered[v].view.camera);
    per_image += iou(now, rendered[v].mask) / rendered.size();
    if (set.segmentDue(false)) {
      due_at.push_back(set.size());
      last = set.segment();
    }
  }
  EXPECT_EQ(due_at, (std::vector<size_t>{4, 6, 9}));
  EXPECT_FALSE(set.segmentDue(false));
  ASSERT_TRUE(set.segmentDue(true)) << "views 10 to 12 came since";
  last = set.segment();
  EXPECT_FALSE(set.segmentDue(true));
  ASSERT_EQ(last.masks.size(), rendered.size());
  double together = 0.0;
  for (size_t v = 0; v < rendered.size(); ++v) {
    EXPECT_EQ(last.names[v], rendered[v].view.name);
    together += iou(last.masks[v], rendered[v].mask) / rendered.size();
  }
  std::cout << "one at a time: per image " << per_image << ", together " << together << " ("
            << last.report.method << ")\n";
  EXPECT_EQ(last.report.method, "views");
  EXPECT_GT(together, 0.95);
  EXPECT_GT(together, per_image + 0.03);
  EXPECT_GT(set.memoryBytes(), 12u * 100u * 75u * 3u) << "the photographs at the working size";
  // Another size than the first view's, and a set that keeps no more than it may.
  cv::Mat other;
  cv::resize(rendered[0].image, other, cv::Size(160, 120));
  EXPECT_THROW(set.add("other", other, rendered[0].view.camera), std::invalid_argument);
  ViewSilhouetteSet small(SilhouetteConfig(), 2);
  for (size_t v = 0; v < 3; ++v) {
    EXPECT_FALSE(
        small.add(rendered[v].view.name, rendered[v].image, rendered[v].view.camera).empty());
  }
  EXPECT_EQ(small.size(), 2u);
  EXPECT_EQ(small.notKept(), 1u);
  EXPECT_THROW(ViewSilhouetteSet(SilhouetteConfig(), 1), std::invalid_argument);
}

}  // namespace
}  // namespace sift_hull
