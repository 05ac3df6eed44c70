#include "formats/input_file.h"

#include "formats/file_error.h"

namespace rsibr {

void require_regular_file(const std::filesystem::path& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status s = fs::status(path, ec);
  if (ec || !fs::exists(s)) throw FileError(path.string(), "no such file");
  if (fs::is_directory(s)) throw FileError(path.string(), "is a folder, expected a file");
  if (!fs::is_regular_file(s)) throw FileError(path.string(), "not a regular file (a FIFO, a socket or a device)");
}

}  // namespace rsibr
