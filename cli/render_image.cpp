#include "cli/render_image.h"

#include "formats/exr_file.h"
#include "formats/exr_io.h"
#include "formats/map_set.h"
#include "core/texel_audit.h"
#include "core/text.h"

#include <cmath>
#include <iostream>
#include <optional>
#include <stdexcept>

namespace rsibr::cli {

EnvMap read_environment_input(const std::string& path, const std::string& layout, bool sanitize) {
  const std::optional<LayoutKind> hint =
      layout.empty() ? std::nullopt : std::optional<LayoutKind>(parse_layout_kind(layout));
  EnvReadReport report;
  EnvMap env = read_environment(path, hint, &report);
  if (report.texels.bad() && !sanitize)
    throw std::runtime_error(path + ": " + report.texels.describe() + "; pass --sanitize to zero them");
  if (sanitize) sanitize_texels(env.pixels);
  // Lossy-compression ringing: never integrated as negative light nor zeroed (energy added).
  if (const std::string folded = fold_environment_ringing(env, path, report, sanitize); !folded.empty())
    std::cerr << "rsibr: warning: " << folded << "\n";
  return env;
}

void write_render_exr(const std::string& path, const cv::Mat& rgba, const Camera& cam,
                      const std::map<std::string, std::string>& strings, const std::map<std::string, int>& ints) {
  if (rgba.type() != CV_32FC4) throw std::logic_error("write_render_exr: the image must be CV_32FC4");
  ExrPartOut part;
  for (int k = 0; k < 4; ++k) part.channels.push_back({std::string(1, "RGBA"[k]), rgba, k});
  for (const auto& [key, value] : strings) part.attributes.emplace_back("rsibr." + key, value);
  for (const auto& [key, value] : ints) part.attributes.emplace_back("rsibr." + key, value);
  part.attributes.emplace_back("rsibr.eye", cam.eye);
  part.attributes.emplace_back("rsibr.worldFromCam", cam.world_from_cam);
  Mat3 K;
  K << cam.fx, 0, cam.cx, 0, cam.fy, cam.cy, 0, 0, 1;
  part.attributes.emplace_back("rsibr.intrinsics", K);
  write_exr(path, {part});
}

}  // namespace rsibr::cli
