// Where tests find the CC0 real-world data fetched by scripts/fetch-assets.sh.
#pragma once

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

namespace rsibr::testing {

inline std::filesystem::path assets_dir() {
  if (const char* c = std::getenv("RSIBR_CACHE_DIR"); c && *c) return std::filesystem::path(c) / "assets";
  return std::filesystem::path(RSIBR_CACHE_DIR) / "assets";
}

// The Poly Haven environments of @pmndrs/assets (empty when not fetched).
inline std::vector<std::filesystem::path> real_environments() {
  std::vector<std::filesystem::path> out;
  const auto dir = assets_dir() / "hdri";
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator(dir, ec))
    if (e.path().extension() == ".exr") out.push_back(e.path());
  std::sort(out.begin(), out.end());
  return out;
}

// A fresh folder under the system temporary folder, removed with everything in it.
class TempDir {
 public:
  TempDir() {
    static std::atomic<int> counter{0};
    path_ = std::filesystem::temp_directory_path() /
            ("rsibr_test_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  std::string file(const std::string& name) const { return (path_ / name).string(); }
  const std::filesystem::path& path() const { return path_; }
  std::vector<std::string> entries() const {
    std::vector<std::string> out;
    for (const auto& e : std::filesystem::directory_iterator(path_)) out.push_back(e.path().filename().string());
    std::sort(out.begin(), out.end());
    return out;
  }

 private:
  std::filesystem::path path_;
};

inline const char* kNoAssets = "real environments not found: run scripts/fetch-assets.sh (needs the npm registry)";

}  // namespace rsibr::testing
