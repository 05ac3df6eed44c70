// Where tests find the CC0 real-world data fetched by scripts/fetch-assets.sh.
#pragma once

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

inline const char* kNoAssets = "real environments not found: run scripts/fetch-assets.sh (needs the npm registry)";

}  // namespace rsibr::testing
