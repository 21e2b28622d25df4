#include "bench_report.h"

#include <ctime>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <stdexcept>

namespace sift_hull {
namespace cli {

std::string fixed(double value, int digits) {
  std::ostringstream out;
  out << std::fixed << std::setprecision(digits) << value;
  return out.str();
}

std::string measurementsMarkdown(const nlohmann::json& measurements) {
  std::ostringstream out;
  out << "### Measurements for the targets\n\n";
  for (const auto& [name, value] : measurements.items()) {
    out << "- `" << name << "`: ";
    if (value.is_number()) {
      out << std::setprecision(4) << value.get<double>();
    } else if (value.is_string()) {
      out << value.get<std::string>();
    } else {
      out << value.dump();
    }
    out << '\n';
  }
  return out.str();
}

std::string todayUtc() {
  const std::time_t now = std::time(nullptr);
  char date[32];
  std::strftime(date, sizeof date, "%Y-%m-%d", std::gmtime(&now));
  return date;
}

void replaceMarkedSection(const std::string& path, const std::string& name,
                          const std::string& content) {
  std::ifstream in(path);
  std::stringstream buffer;
  buffer << in.rdbuf();
  std::string text = buffer.str();
  const std::string begin = "<!-- begin " + name + " -->\n", end = "<!-- end " + name + " -->\n";
  const size_t first = text.find(begin), last = text.find(end);
  const std::string section = begin + content + end;
  if (first == std::string::npos || last == std::string::npos || last < first) {
    text += (text.empty() || text.back() == '\n' ? "\n" : "\n\n") + section;
  } else {
    text.replace(first, last + end.size() - first, section);
  }
  std::ofstream out(path);
  if (!(out << text)) throw std::runtime_error(path + ": cannot write");
}

}  // namespace cli
}  // namespace sift_hull
