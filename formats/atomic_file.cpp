#include "formats/atomic_file.h"

#include "formats/file_error.h"
#include "formats/written_file_check.h"

#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <stdexcept>

namespace rsibr {

namespace {

void write_checked(const std::filesystem::path& target, const std::function<void(const std::string&)>& writer,
                   bool empty_allowed) {
  static std::atomic<int> counter{0};
  // Keep the extension last so format-sniffing writers (OpenCV) still see it.
  std::filesystem::path tmp = target;
  tmp.replace_filename("." + target.stem().string() + ".tmp" + std::to_string(::getpid()) + "-" +
                       std::to_string(counter++) + target.extension().string());
  try {
    writer(tmp.string());
    check_written_file(tmp, target, empty_allowed);
    std::filesystem::rename(tmp, target);
    note_checked_file(target);
  } catch (...) {
    std::error_code ec;
    std::filesystem::remove(tmp, ec);
    throw;
  }
}

}  // namespace

void write_atomically(const std::filesystem::path& target, const std::function<void(const std::string&)>& writer) {
  write_checked(target, writer, false);
}

void write_text_atomically(const std::filesystem::path& target, const std::string& text) {
  write_checked(
      target,
      [&](const std::string& tmp) {
        std::ofstream f(tmp, std::ios::binary);
        f.write(text.data(), std::streamsize(text.size()));
        f.close();
        if (!f)
          throw FileError(target.string(), std::string("cannot write: ") + std::strerror(errno), {}, FileRole::Output);
      },
      text.empty());
}

void check_not_same_file(const std::filesystem::path& input, const std::filesystem::path& output) {
  std::error_code ec;
  if (std::filesystem::exists(output, ec) && std::filesystem::equivalent(input, output, ec))
    throw std::invalid_argument(output.string() + ": output would overwrite the input");
}

}  // namespace rsibr
