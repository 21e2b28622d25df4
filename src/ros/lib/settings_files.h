#pragma once

// The files that derive from the nodes' settings tables (sift_hull/settings.h): the parameter
// files config/hull.yaml and config/matcher.yaml, cfg/Matcher.cfg (matcher_node's
// dynamic_reconfigure fields) and the parameter tables of docs/NODES.md. `sift_hull_ros settings
// --write` writes them; test_settings_files checks that the checked-in files are current.

#include <string>
#include <vector>

namespace sift_hull {
namespace settings_files {

/// One derived file: its path relative to the package root and the text it must hold.
struct DerivedFile {
  std::string path;
  std::string text;
};

/// A node's private parameters as a YAML parameter file: every parameter with its default and a
/// comment (help, unit, range). node: "hull_node" or "matcher_node".
std::string parameterYaml(const std::string& node);

/// cfg/Matcher.cfg: the run-time settings of matcher_node, with their defaults and ranges.
std::string matcherReconfigureCfg();

/// A node's parameters as a Markdown table (Name, Type, Default, Unit, Range, Run time,
/// Description). node: "hull_node", "matcher_node" or "save_results".
std::string parameterTable(const std::string& node);

/// `document` with the text between the lines <!-- BEGIN GENERATED PARAMETERS node --> and
/// <!-- END GENERATED PARAMETERS node --> replaced by parameterTable(node), for each node whose
/// markers it holds.
std::string withParameterTables(const std::string& document);

/// Every derived file, as it must read; `root` is the package's folder (docs/NODES.md is read
/// from there to splice its tables in). Throws std::runtime_error when docs/NODES.md is missing.
std::vector<DerivedFile> derivedFiles(const std::string& root);

}  // namespace settings_files
}  // namespace sift_hull
