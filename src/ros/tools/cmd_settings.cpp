// sift_hull_ros settings: writes or checks the files derived from the nodes' settings tables.

#include <fstream>
#include <iostream>
#include <sstream>

#include "args.h"
#include "lib/settings_files.h"

namespace sift_hull {
namespace cli {

int runSettings(const std::vector<std::string>& args) {
  ArgParser parser("settings",
                   "Writes (--write) or checks the files derived from the nodes' settings\n"
                   "tables: config/hull.yaml, config/matcher.yaml, cfg/Matcher.cfg and the\n"
                   "parameter tables of docs/NODES.md. Without --write, exits 1 when one is not\n"
                   "current and names it.");
  parser.addOption("root", "DIR", "the package's folder", ".");
  parser.addFlag("write", "write the files instead of checking them");
  if (!parser.parse(args)) return 0;
  const std::string root = parser.get("root");
  int stale = 0;
  for (const settings_files::DerivedFile& file : settings_files::derivedFiles(root)) {
    const std::string path = root + "/" + file.path;
    if (parser.flag("write")) {
      std::ofstream(path) << file.text;
      std::cout << "wrote " << path << '\n';
      continue;
    }
    std::ifstream in(path);
    std::ostringstream text;
    text << in.rdbuf();
    if (text.str() == file.text) continue;
    std::cout << path << " is not current: sift_hull_ros settings --write --root " << root << '\n';
    ++stale;
  }
  return stale == 0 ? 0 : 1;
}

}  // namespace cli
}  // namespace sift_hull
