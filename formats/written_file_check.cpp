#include "formats/written_file_check.h"

#include "formats/exr_file.h"
#include "formats/file_error.h"

#include <fcntl.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <map>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <vector>

namespace rsibr {
namespace fs = std::filesystem;
namespace {

[[noreturn]] void refuse(const fs::path& shown, const std::string& why) {
  throw FileError(shown.string(), "cannot write: " + why, {}, FileRole::Output);
}

void sync_to_disk(const fs::path& file, const fs::path& shown) {
  const int fd = ::open(file.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) refuse(shown, std::strerror(errno));
  const int rc = ::fsync(fd);
  const int err = errno;
  ::close(fd);
  // EINVAL: a file system without fsync (some FUSE mounts); nothing to learn there.
  if (rc != 0 && err != EINVAL) refuse(shown, std::strerror(err));
}

std::vector<unsigned char> tail_bytes(const fs::path& file, std::size_t n) {
  std::ifstream in(file, std::ios::binary);
  in.seekg(0, std::ios::end);
  const auto size = std::size_t(in.tellg());
  n = std::min(n, size);
  std::vector<unsigned char> bytes(n);
  in.seekg(std::streamoff(size - n));
  in.read(reinterpret_cast<char*>(bytes.data()), std::streamsize(n));
  return bytes;
}

bool ends_with(const std::vector<unsigned char>& bytes, const std::vector<unsigned char>& end) {
  return bytes.size() >= end.size() && std::equal(end.rbegin(), end.rend(), bytes.rbegin());
}

struct FileState {
  std::uintmax_t size = 0;
  fs::file_time_type modified;
  bool operator==(const FileState& o) const { return size == o.size && modified == o.modified; }
};

std::mutex checked_mutex;
std::map<fs::path, FileState>& checked_files() {
  static std::map<fs::path, FileState> files;
  return files;
}

std::optional<FileState> state_of(const fs::path& file) {
  std::error_code ec;
  FileState s;
  s.size = fs::file_size(file, ec);
  if (ec) return std::nullopt;
  s.modified = fs::last_write_time(file, ec);
  if (ec) return std::nullopt;
  return s;
}

bool already_checked(const fs::path& file) {
  const auto now = state_of(file);
  const std::lock_guard lock(checked_mutex);
  const auto it = checked_files().find(fs::absolute(file));
  return now && it != checked_files().end() && it->second == *now;
}

std::string lower_extension(const fs::path& p) {
  std::string e = p.extension().string();
  for (char& c : e) c = char(std::tolower(static_cast<unsigned char>(c)));
  return e;
}

}  // namespace

void check_written_file(const fs::path& file, const fs::path& shown, bool empty_allowed) {
  std::error_code ec;
  if (!fs::is_regular_file(file, ec)) refuse(shown, "the file is missing after writing");
  sync_to_disk(file, shown);
  const auto size = fs::file_size(file, ec);
  if (ec) refuse(shown, ec.message());
  if (size == 0) {
    if (empty_allowed) return;
    refuse(shown, "nothing reached the file (is the disk full?)");
  }
  if (already_checked(file)) return;
  const std::string ext = lower_extension(shown);
  if (ext == ".exr") {
    if (!exr_reads_back(file.string())) refuse(shown, "the EXR read back is broken (is the disk full?)");
  } else if (ext == ".png") {
    static const std::vector<unsigned char> iend = {0, 0, 0, 0, 'I', 'E', 'N', 'D', 0xAE, 0x42, 0x60, 0x82};
    if (!ends_with(tail_bytes(file, iend.size()), iend))
      refuse(shown, "the PNG read back is truncated (is the disk full?)");
  } else if (ext == ".jpg" || ext == ".jpeg") {
    if (!ends_with(tail_bytes(file, 2), {0xFF, 0xD9}))
      refuse(shown, "the JPEG read back is truncated (is the disk full?)");
  } else if (ext == ".json") {
    std::ifstream in(file, std::ios::binary);
    if (!nlohmann::json::accept(in)) refuse(shown, "the JSON read back is truncated (is the disk full?)");
  }
}

void note_checked_file(const fs::path& file) {
  const auto now = state_of(file);
  if (!now) return;
  const std::lock_guard lock(checked_mutex);
  checked_files()[fs::absolute(file)] = *now;
}

}  // namespace rsibr
