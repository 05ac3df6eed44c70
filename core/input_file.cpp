#include "core/input_file.h"

#include <stdexcept>

namespace rsibr {

void require_regular_file(const std::filesystem::path& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status s = fs::status(path, ec);
  if (ec || !fs::exists(s)) throw std::invalid_argument(path.string() + ": no such file");
  if (fs::is_directory(s)) throw std::invalid_argument(path.string() + ": is a folder, expected a file");
  if (!fs::is_regular_file(s))
    throw std::invalid_argument(path.string() + ": not a regular file (a FIFO, a socket or a device)");
}

}  // namespace rsibr
