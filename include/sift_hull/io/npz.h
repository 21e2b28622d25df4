#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace sift_hull {

struct NpzMemoryFile;

/// A numpy .npz file: a zip archive of .npy files, stored (np.savez) or deflated
/// (np.savez_compressed). Zip64 archives are read too. The entries are read one at a time, each
/// only up to a size the caller gives, so a small file cannot ask for a large allocation.
class NpzReader {
 public:
  /// Opens the archive and lists its entries. Throws ParseError "FILE: what" when the file cannot
  /// be opened, is not a zip archive, has more than `max_entries` entries, or names an entry twice.
  NpzReader(const std::string& path, uint64_t max_entries);
  /// The same for an archive held in memory; `name` stands for the file in errors.
  NpzReader(const std::string& name, std::string bytes, uint64_t max_entries);
  ~NpzReader();
  NpzReader(const NpzReader&) = delete;
  NpzReader& operator=(const NpzReader&) = delete;

  const std::string& path() const { return path_; }
  /// The entries' names in the archive's order (names longer than 1024 bytes are left out).
  const std::vector<std::string>& names() const { return names_; }
  bool has(const std::string& name) const { return entries_.count(name) > 0; }
  /// The decompressed bytes of an entry. Throws ParseError "FILE: NAME: what" for a missing or
  /// encrypted entry, one whose decompressed size exceeds `max_bytes` (checked before anything is
  /// allocated), a compression method other than stored or deflate, a truncated or corrupt entry
  /// or a CRC mismatch.
  std::string read(const std::string& name, uint64_t max_bytes) const;

 private:
  struct Position {
    uint64_t directory_offset;
    uint64_t entry_number;
  };
  friend struct NpzMemoryFile;
  struct Memory {
    std::string bytes;
    uint64_t position = 0;
  };
  void open(const std::string& path, uint64_t max_entries);

  std::string path_;
  std::unique_ptr<Memory> memory_;  // the archive's bytes when read from memory
  void* zip_ = nullptr;             // unzFile
  std::vector<std::string> names_;
  std::map<std::string, Position> entries_;
};

/// The bytes of a .npy file (format 1.0, C order) holding `matrix` as a little-endian float64
/// array of shape (rows, cols).
std::string npyBytes(const Eigen::MatrixXd& matrix);

/// Writes an .npz archive of the given (name, bytes) entries, stored uncompressed as np.savez
/// does. Throws std::runtime_error when the file cannot be written.
void writeNpz(const std::string& path,
              const std::vector<std::pair<std::string, std::string>>& entries);

}  // namespace sift_hull
