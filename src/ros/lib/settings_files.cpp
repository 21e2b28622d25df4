#include "lib/settings_files.h"

#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "lib/result_saver.h"
#include "nodes/hull_node_config.h"
#include "nodes/matcher_node_config.h"

namespace sift_hull {
namespace settings_files {
namespace {

/// What a derived file says of itself in its first lines.
constexpr const char* kDerivedNote =
    "Generated from the settings tables by `sift_hull_ros settings --write`; do not edit.";

/// The name, type and description of every setting, with its value in the default config.
struct Row {
  SettingInfo info;
  SettingValue value;
};

template <typename Config>
std::vector<Row> rowsOf(const SettingTable<Config>& table) {
  std::vector<Row> rows;
  const Config defaults;
  for (const Setting<Config>& s : table.settings()) rows.push_back({s.info, s.get(defaults)});
  return rows;
}

std::vector<Row> nodeRows(const std::string& node) {
  if (node == "hull_node") return rowsOf(settingsOf<HullNodeSettings>());
  if (node == "matcher_node") return rowsOf(settingsOf<MatcherSettings>());
  if (node == "save_results") return rowsOf(settingsOf<ResultSaverConfig>());
  throw std::invalid_argument("no node " + node);
}

/// A number as YAML 1.1 reads it back as the same type: doubles always with a point.
std::string yamlNumber(double value) {
  std::string text = settingText(value);
  if (text.find_first_of(".en") == std::string::npos) return text + ".0";
  const size_t e = text.find('e');
  if (e != std::string::npos && text.find('.') == std::string::npos) text.insert(e, ".0");
  return text;
}

std::string yamlValue(const SettingValue& value) {
  if (const double* d = std::get_if<double>(&value)) return yamlNumber(*d);
  if (const auto* list = std::get_if<std::vector<double>>(&value)) {
    std::string text = "[";
    for (size_t i = 0; i < list->size(); ++i) text += (i ? ", " : "") + yamlNumber((*list)[i]);
    return text + "]";
  }
  return settingText(value);
}

std::string pythonString(const std::string& text) {
  std::string quoted = "\"";
  for (char c : text) quoted += (c == '"' || c == '\\') ? std::string("\\") + c : std::string(1, c);
  return quoted + "\"";
}

std::string pythonBound(double bound) { return std::isfinite(bound) ? yamlNumber(bound) : "None"; }

std::string cfgLine(const Row& row) {
  const char* type = "double_t";
  std::string value = yamlValue(row.value);
  if (row.info.type == SettingType::kBool) {
    type = "bool_t";
    value = std::get<bool>(row.value) ? "True" : "False";
  } else if (row.info.type == SettingType::kInt) {
    type = "int_t";
  } else if (row.info.type == SettingType::kString) {
    type = "str_t";
    value = pythonString(std::get<std::string>(row.value));
  }
  std::string line = "gen.add(" + pythonString(row.info.name) + ", " + type + ", 0, " +
                     pythonString(settingDescription(row.info)) + ", " + value;
  if (row.info.type == SettingType::kInt || row.info.type == SettingType::kDouble) {
    line += ", " + pythonBound(row.info.min) + ", " + pythonBound(row.info.max);
  }
  return line + ")\n";
}

std::string markdownCell(std::string text) {
  std::string escaped;
  for (char c : text) escaped += c == '|' ? std::string("\\|") : std::string(1, c);
  return escaped;
}

std::string readFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read " + path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace

std::string parameterYaml(const std::string& node) {
  std::string text =
      "# " + node + "'s private parameters, every one it reads, with their defaults.\n";
  text += "# " + std::string(kDerivedNote) + "\n";
  text += "# Reference: docs/NODES.md.\n";
  for (const Row& row : nodeRows(node)) {
    text +=
        row.info.name + ": " + yamlValue(row.value) + "  # " + settingDescription(row.info) + "\n";
  }
  return text;
}

std::string matcherReconfigureCfg() {
  std::string text =
      "#!/usr/bin/env python3\n"
      "\"\"\"matcher_node's settings tuned at run time. " +
      std::string(kDerivedNote) +
      "\"\"\"\n"
      "from dynamic_reconfigure.parameter_generator_catkin import ParameterGenerator, bool_t, "
      "double_t, int_t, str_t\n\n"
      "gen = ParameterGenerator()\n";
  for (const Row& row : nodeRows("matcher_node")) {
    if (row.info.runtime) text += cfgLine(row);
  }
  return text + "\nexit(gen.generate(\"sift_hull\", \"matcher_node\", \"Matcher\"))\n";
}

std::string parameterTable(const std::string& node) {
  std::string text = "<!-- " + std::string(kDerivedNote) +
                     " -->\n\n"
                     "| Name | Type | Default | Unit | Range | Run time | Description |\n"
                     "| --- | --- | --- | --- | --- | --- | --- |\n";
  for (const Row& row : nodeRows(node)) {
    text += "| `~" + row.info.name + "` | " + settingTypeName(row.info.type) + " | `" +
            markdownCell(settingText(row.value)) + "` | " + row.info.unit + " | " +
            markdownCell(settingRangeText(row.info)) + " | " + (row.info.runtime ? "yes" : "") +
            " | " + markdownCell(row.info.help) + " |\n";
  }
  return text;
}

std::string withParameterTables(const std::string& document) {
  std::string text = document;
  for (const std::string node : {"hull_node", "matcher_node", "save_results"}) {
    const std::string begin = "<!-- BEGIN GENERATED PARAMETERS " + node + " -->\n";
    const std::string end = "<!-- END GENERATED PARAMETERS " + node + " -->";
    const size_t from = text.find(begin);
    // Every node's table must be there: a deleted marker would leave a node without reference.
    if (from == std::string::npos) throw std::runtime_error("no begin marker for " + node);
    const size_t to = text.find(end, from);
    if (to == std::string::npos) throw std::runtime_error("no end marker for " + node);
    text.replace(from + begin.size(), to - from - begin.size(), parameterTable(node));
  }
  return text;
}

std::vector<DerivedFile> derivedFiles(const std::string& root) {
  return {{"config/hull.yaml", parameterYaml("hull_node")},
          {"config/matcher.yaml", parameterYaml("matcher_node")},
          {"cfg/Matcher.cfg", matcherReconfigureCfg()},
          {"docs/NODES.md", withParameterTables(readFile(root + "/docs/NODES.md"))}};
}

}  // namespace settings_files
}  // namespace sift_hull
