// matcher_node's dynamic_reconfigure mapping and the files derived from the settings tables:
// cfg/Matcher.cfg starts where the config structs do, the mapping carries every run-time setting
// both ways and refuses what the table refuses, and config/*.yaml, cfg/Matcher.cfg and
// docs/NODES.md are what the tables give.

#include <gtest/gtest.h>

#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>

#include "lib/reconfigure_settings.h"
#include "lib/settings_files.h"
#include "nodes/hull_node_config.h"
#include "nodes/matcher_node_config.h"
#include "sift_hull/MatcherConfig.h"

namespace sift_hull {
namespace {

using ros_conversions::applyReconfigure;
using ros_conversions::reconfigureMessage;

dynamic_reconfigure::Config messageOf(const MatcherConfig& config) {
  dynamic_reconfigure::Config message;
  config.__toMessage__(message);
  return message;
}

TEST(MatcherReconfigure, DefaultsEqualTheConfigStructs) {
  const dynamic_reconfigure::Config cfg = messageOf(MatcherConfig::__getDefault__());
  const dynamic_reconfigure::Config table =
      reconfigureMessage(settingsOf<MatcherSettings>(), MatcherSettings());
  EXPECT_EQ(cfg.doubles, table.doubles);
  EXPECT_EQ(cfg.bools, table.bools);
  EXPECT_EQ(cfg.ints, table.ints);
  EXPECT_EQ(cfg.strs, table.strs);
  EXPECT_GE(table.doubles.size(), 14u);
}

TEST(MatcherReconfigure, EveryRunTimeSettingGoesBothWays) {
  MatcherSettings tuned;
  tuned.matching.ratio = 0.7;
  tuned.matching.cross_check = true;
  tuned.filters.lsc.max_relative_error = 0.5;
  tuned.filters.gsc.max_histogram_distance = 0.25;
  tuned.filters.vote_ransac.max_scale_ratio = 3.0;
  MatcherConfig config = MatcherConfig::__getDefault__();
  dynamic_reconfigure::Config message = reconfigureMessage(settingsOf<MatcherSettings>(), tuned);
  ASSERT_TRUE(config.__fromMessage__(message));
  EXPECT_EQ(config.ratio, 0.7);
  EXPECT_EQ(config.lsc_max_relative_error, 0.5);
  MatcherSettings back;
  applyReconfigure(settingsOf<MatcherSettings>(), messageOf(config), &back);
  EXPECT_EQ(back.matching.ratio, 0.7);
  EXPECT_TRUE(back.matching.cross_check);
  EXPECT_EQ(back.filters.lsc.max_relative_error, 0.5);
  EXPECT_EQ(back.filters.gsc.max_histogram_distance, 0.25);
  EXPECT_EQ(back.filters.vote_ransac.max_scale_ratio, 3.0);
}

TEST(MatcherReconfigure, RefusesWhatTheTableRefuses) {
  MatcherSettings settings;
  dynamic_reconfigure::Config nan;
  nan.doubles.resize(1);
  nan.doubles[0].name = "max_descriptor_distance";
  nan.doubles[0].value = std::nan("");
  EXPECT_THROW(applyReconfigure(settingsOf<MatcherSettings>(), nan, &settings),
               std::invalid_argument);
  dynamic_reconfigure::Config zero = nan;
  zero.doubles[0].name = "magsac_max_epipolar_px";
  zero.doubles[0].value = 0.0;  // the cfg's closed range admits 0, the setting does not
  EXPECT_THROW(applyReconfigure(settingsOf<MatcherSettings>(), zero, &settings),
               std::invalid_argument);
  dynamic_reconfigure::Config not_run_time = nan;
  not_run_time.doubles[0].name = "sigma_px";
  not_run_time.doubles[0].value = 2.0;
  EXPECT_THROW(applyReconfigure(settingsOf<MatcherSettings>(), not_run_time, &settings),
               std::invalid_argument);
}

TEST(SettingsTables, EachNodeNamesEveryParameterOnce) {
  for (const auto& names : {[] {
                              std::vector<std::string> n;
                              for (const auto& s : settingsOf<HullNodeSettings>().settings())
                                n.push_back(s.info.name);
                              return n;
                            }(),
                            [] {
                              std::vector<std::string> n;
                              for (const auto& s : settingsOf<MatcherSettings>().settings())
                                n.push_back(s.info.name);
                              return n;
                            }()}) {
    EXPECT_GE(names.size(), 30u);
    EXPECT_EQ(std::set<std::string>(names.begin(), names.end()).size(), names.size());
  }
}

TEST(SettingsTables, TheDefaultsAreInRange) {
  EXPECT_NO_THROW(settingsOf<HullNodeSettings>().checkRanges(HullNodeSettings()));
  EXPECT_NO_THROW(settingsOf<MatcherSettings>().checkRanges(MatcherSettings()));
}

TEST(SettingsFiles, TheDerivedFilesAreCurrent) {
  const std::string root = SIFT_HULL_SOURCE_DIR;
  for (const settings_files::DerivedFile& file : settings_files::derivedFiles(root)) {
    std::ifstream in(root + "/" + file.path);
    ASSERT_TRUE(in) << file.path;
    std::ostringstream text;
    text << in.rdbuf();
    EXPECT_EQ(text.str(), file.text)
        << file.path << " is not current: run sift_hull_ros settings --write --root " << root;
  }
}

TEST(SettingsFiles, TheNodeReferenceHasATableForEachNode) {
  std::string stale;
  for (const char* node : {"hull_node", "matcher_node", "save_results"}) {
    stale += "<!-- BEGIN GENERATED PARAMETERS " + std::string(node) + " -->\nSTALE TEXT\n" +
             "<!-- END GENERATED PARAMETERS " + node + " -->\n";
  }
  const std::string doc = settings_files::withParameterTables(stale);
  EXPECT_EQ(doc.find("STALE TEXT"), std::string::npos);
  EXPECT_NE(doc.find("| `~max_depth` | integer | `8` | levels | [2, 10] |"), std::string::npos)
      << doc;
  EXPECT_NE(doc.find("| `~box` |"), std::string::npos);
  EXPECT_NE(doc.find("| `~gsc_max_histogram_distance` |"), std::string::npos) << doc;
  // A node's table missing from the reference is an error, not a silent pass.
  EXPECT_THROW(settings_files::withParameterTables("<!-- BEGIN GENERATED PARAMETERS hull_node -->\n"
                                                   "<!-- END GENERATED PARAMETERS hull_node -->\n"),
               std::runtime_error);
}

}  // namespace
}  // namespace sift_hull
