#pragma once
// The readers under fuzzing take file paths: each input is written to one file in a temporary
// directory of this process ($TMPDIR or /tmp), removed at exit.

#include <stdlib.h>
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <fstream>
#include <string>

namespace sift_hull {
namespace fuzz {

class InputFile {
 public:
  /// `name` is the file's name inside the directory, e.g. "input.pfm".
  explicit InputFile(const std::string& name) {
    const char* base = std::getenv("TMPDIR");
    std::string pattern = std::string(base && *base ? base : "/tmp") + "/sift_hull_fuzz_XXXXXX";
    if (mkdtemp(pattern.data()) == nullptr) {
      std::perror("mkdtemp");
      std::abort();
    }
    directory_ = pattern;
    path_ = directory_ + "/" + name;
  }
  ~InputFile() {
    std::remove(path_.c_str());
    rmdir(directory_.c_str());
  }
  InputFile(const InputFile&) = delete;
  InputFile& operator=(const InputFile&) = delete;

  /// Replaces the file's contents with the input's bytes and returns its path.
  const std::string& write(const uint8_t* data, size_t size) const {
    std::ofstream out(path_, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
    out.close();
    if (!out) {
      std::perror(path_.c_str());
      std::abort();
    }
    return path_;
  }

 private:
  std::string directory_;
  std::string path_;
};

/// The input's bytes as a file named `name`, passed to `read`; any std::exception is an accepted
/// outcome (the reader refused the file).
template <typename Reader>
void readAsFile(const char* name, const uint8_t* data, size_t size, Reader read) {
  static const InputFile file(name);  // one per harness process, removed at exit
  const std::string& path = file.write(data, size);
  try {
    read(path);
  } catch (const std::exception&) {
  }
}

}  // namespace fuzz
}  // namespace sift_hull
