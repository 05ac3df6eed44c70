// Shared by the fuzz targets: the readers under test take paths (OpenEXR, OpenCV, mrcal and the
// mesh loaders read files), so each input is written to a file of this process's own first.
#pragma once

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

namespace rsibr::fuzz {

// The input as a file named "input<extension>" in a folder of this process (removed at exit).
inline std::string input_file(const std::uint8_t* data, std::size_t size, const std::string& extension) {
  static const std::filesystem::path dir = [] {
    std::filesystem::path d = std::filesystem::temp_directory_path() / ("rsibr-fuzz-" + std::to_string(::getpid()));
    std::filesystem::create_directories(d);
    return d;
  }();
  const std::filesystem::path p = dir / ("input" + extension);
  std::ofstream(p, std::ios::binary | std::ios::trunc)
      .write(reinterpret_cast<const char*>(data), std::streamsize(size));
  return p.string();
}

}  // namespace rsibr::fuzz
