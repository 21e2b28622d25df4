// numpy .npz archives (sift_hull/io/npz.h), read and written with minizip.

#include "sift_hull/io/npz.h"

#include <unzip.h>
#include <zip.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <stdexcept>

#include "sift_hull/io/calibration.h"

namespace sift_hull {
namespace {

/// Entry names longer than this are listed by no reader of the package.
constexpr uLong kMaxEntryNameBytes = 1024;

[[noreturn]] void fail(const std::string& file, const std::string& message) {
  throw ParseError(file, 0, message);
}

std::string zipError(int code) {
  switch (code) {
    case UNZ_CRCERROR:
      return "its CRC-32 does not match its contents";
    case UNZ_BADZIPFILE:
      return "a malformed zip entry";
    case UNZ_ERRNO:
      return "the file cannot be read";
    default:
      return "corrupt data (minizip error " + std::to_string(code) + ")";
  }
}

}  // namespace

// minizip's file functions over an archive in memory: `opaque` is the NpzReader::Memory.
struct NpzMemoryFile {
  static voidpf ZCALLBACK open(voidpf opaque, const void*, int mode) {
    if (mode & ZLIB_FILEFUNC_MODE_CREATE) return nullptr;
    return opaque;
  }
  static uLong ZCALLBACK read(voidpf opaque, voidpf, void* buffer, uLong size) {
    auto* memory = static_cast<NpzReader::Memory*>(opaque);
    if (memory->position >= memory->bytes.size()) return 0;
    const uint64_t count = std::min<uint64_t>(size, memory->bytes.size() - memory->position);
    std::memcpy(buffer, memory->bytes.data() + memory->position, count);
    memory->position += count;
    return static_cast<uLong>(count);
  }
  static uLong ZCALLBACK write(voidpf, voidpf, const void*, uLong) { return 0; }
  static ZPOS64_T ZCALLBACK tell(voidpf opaque, voidpf) {
    return static_cast<NpzReader::Memory*>(opaque)->position;
  }
  static long ZCALLBACK seek(voidpf opaque, voidpf, ZPOS64_T offset, int origin) {
    auto* memory = static_cast<NpzReader::Memory*>(opaque);
    const uint64_t base = origin == ZLIB_FILEFUNC_SEEK_SET   ? 0
                          : origin == ZLIB_FILEFUNC_SEEK_CUR ? memory->position
                                                             : memory->bytes.size();
    if (offset > UINT64_MAX - base) return -1;
    memory->position = base + offset;  // past the end reads nothing, as with a file
    return 0;
  }
  static int ZCALLBACK close(voidpf, voidpf) { return 0; }
  static int ZCALLBACK error(voidpf, voidpf) { return 0; }
};

NpzReader::NpzReader(const std::string& path, uint64_t max_entries) : path_(path) {
  zip_ = unzOpen64(path.c_str());
  open(path, max_entries);
}

NpzReader::NpzReader(const std::string& name, std::string bytes, uint64_t max_entries)
    : path_(name), memory_(new Memory{std::move(bytes), 0}) {
  zlib_filefunc64_def functions;
  functions.zopen64_file = NpzMemoryFile::open;
  functions.zread_file = NpzMemoryFile::read;
  functions.zwrite_file = NpzMemoryFile::write;
  functions.ztell64_file = NpzMemoryFile::tell;
  functions.zseek64_file = NpzMemoryFile::seek;
  functions.zclose_file = NpzMemoryFile::close;
  functions.zerror_file = NpzMemoryFile::error;
  functions.opaque = memory_.get();
  zip_ = unzOpen2_64(name.c_str(), &functions);
  open(name, max_entries);
}

void NpzReader::open(const std::string& path, uint64_t max_entries) {
  if (zip_ == nullptr) fail(path, "not a zip archive (an .npz file), or it cannot be read");
  try {
    unz_global_info64 global;
    if (unzGetGlobalInfo64(zip_, &global) != UNZ_OK) fail(path, "malformed zip directory");
    if (global.number_entry > max_entries) {
      fail(path, "the archive has " + std::to_string(global.number_entry) +
                     " entries, more than the limit of " + std::to_string(max_entries));
    }
    uint64_t count = 0;
    if (global.number_entry == 0) return;  // an empty archive
    for (int status = unzGoToFirstFile(zip_); status != UNZ_END_OF_LIST_OF_FILE;
         status = unzGoToNextFile(zip_)) {
      if (status != UNZ_OK) fail(path, "malformed zip directory: " + zipError(status));
      if (++count > max_entries) {
        fail(path,
             "the archive has more than the limit of " + std::to_string(max_entries) + " entries");
      }
      unz_file_info64 info;
      char name[kMaxEntryNameBytes + 1] = {};
      if (unzGetCurrentFileInfo64(zip_, &info, name, sizeof(name), nullptr, 0, nullptr, 0) !=
          UNZ_OK) {
        fail(path, "malformed zip directory entry " + std::to_string(count));
      }
      if (info.size_filename > kMaxEntryNameBytes) continue;
      unz64_file_pos position;
      if (unzGetFilePos64(zip_, &position) != UNZ_OK) {
        fail(path, "malformed zip directory entry " + std::to_string(count));
      }
      const std::string entry(name, info.size_filename);
      if (!entries_.emplace(entry, Position{position.pos_in_zip_directory, position.num_of_file})
               .second) {
        fail(path, "the archive holds the entry '" + entry + "' twice");
      }
      names_.push_back(entry);
    }
  } catch (...) {
    unzClose(zip_);
    throw;
  }
}

NpzReader::~NpzReader() { unzClose(zip_); }

std::string NpzReader::read(const std::string& name, uint64_t max_bytes) const {
  const auto found = entries_.find(name);
  if (found == entries_.end()) fail(path_, name + ": no such entry in the archive");
  const auto failEntry = [&](const std::string& message) { fail(path_, name + ": " + message); };
  unz64_file_pos position{found->second.directory_offset, found->second.entry_number};
  unz_file_info64 info;
  if (unzGoToFilePos64(zip_, &position) != UNZ_OK ||
      unzGetCurrentFileInfo64(zip_, &info, nullptr, 0, nullptr, 0, nullptr, 0) != UNZ_OK) {
    failEntry("malformed zip directory entry");
  }
  if (info.flag & 1u) failEntry("the entry is encrypted");
  if (info.compression_method != 0 && info.compression_method != Z_DEFLATED) {
    failEntry("compression method " + std::to_string(info.compression_method) +
              " is not supported (stored or deflate are)");
  }
  if (info.uncompressed_size > max_bytes) {
    failEntry("the entry holds " + std::to_string(info.uncompressed_size) +
              " bytes, more than the limit of " + std::to_string(max_bytes));
  }
  int status = unzOpenCurrentFile(zip_);
  if (status != UNZ_OK) failEntry("cannot open the entry: " + zipError(status));
  std::string bytes(static_cast<size_t>(info.uncompressed_size), '\0');
  size_t got = 0;
  while (got < bytes.size()) {
    const unsigned chunk = static_cast<unsigned>(std::min<size_t>(bytes.size() - got, 1u << 20));
    status = unzReadCurrentFile(zip_, &bytes[got], chunk);
    if (status <= 0) break;
    got += static_cast<size_t>(status);
  }
  const int closed = unzCloseCurrentFile(zip_);
  if (status < 0) failEntry("truncated or corrupt entry: " + zipError(status));
  if (got != bytes.size()) {
    failEntry("truncated entry: " + std::to_string(got) + " of " + std::to_string(bytes.size()) +
              " bytes");
  }
  if (closed != UNZ_OK) failEntry("corrupt entry: " + zipError(closed));
  return bytes;
}

std::string npyBytes(const Eigen::MatrixXd& matrix) {
  std::string header = "{'descr': '<f8', 'fortran_order': False, 'shape': (" +
                       std::to_string(matrix.rows()) + ", " + std::to_string(matrix.cols()) +
                       "), }";
  while ((10 + header.size() + 1) % 64 != 0) header.push_back(' ');
  header.push_back('\n');
  std::string out = "\x93NUMPY";
  out.push_back('\x01');
  out.push_back('\x00');
  out.push_back(static_cast<char>(header.size() & 0xff));
  out.push_back(static_cast<char>(header.size() >> 8));
  out += header;
  for (Eigen::Index r = 0; r < matrix.rows(); ++r) {
    for (Eigen::Index c = 0; c < matrix.cols(); ++c) {
      const double value = matrix(r, c);
      char raw[8];
      std::memcpy(raw, &value, 8);  // little-endian hosts only, as the reader
      out.append(raw, 8);
    }
  }
  return out;
}

void writeNpz(const std::string& path,
              const std::vector<std::pair<std::string, std::string>>& entries) {
  zipFile zip = zipOpen64(path.c_str(), APPEND_STATUS_CREATE);
  if (zip == nullptr) throw std::runtime_error(path + ": cannot write file");
  bool ok = true;
  for (const auto& [name, bytes] : entries) {
    if (bytes.size() >= 0xffffffffu) {
      zipClose(zip, nullptr);
      throw std::runtime_error(path + ": the entry '" + name + "' is 4 GiB or larger");
    }
    zip_fileinfo info{};
    info.tmz_date.tm_mday = 1;  // 1980-01-01, the earliest zip date: the bytes do not vary
    info.tmz_date.tm_year = 1980;
    ok = ok &&
         zipOpenNewFileInZip64(zip, name.c_str(), &info, nullptr, 0, nullptr, 0, nullptr, 0, 0,
                               0) == ZIP_OK &&
         zipWriteInFileInZip(zip, bytes.data(), static_cast<unsigned>(bytes.size())) == ZIP_OK &&
         zipCloseFileInZip(zip) == ZIP_OK;
  }
  ok = zipClose(zip, nullptr) == ZIP_OK && ok;
  if (!ok) throw std::runtime_error(path + ": cannot write file");
}

}  // namespace sift_hull
