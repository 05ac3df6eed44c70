#include "formats/exr_io.h"

#include "formats/exr_file.h"
#include "core/colour.h"
#include "formats/input_file.h"
#include "core/text.h"
#include "formats/image_codecs.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <mutex>
#include <sstream>
#include <stdexcept>

namespace rsibr {
namespace {

[[noreturn]] void refuse(const std::string& path, const std::string& what) { throw FileError(path, what); }

LayoutKind layout_from_shape(const std::string& path, int w, int h) {
  if (w == 2 * h) return LayoutKind::LatLong;
  if (h == 6 * w) return LayoutKind::Cube;
  refuse(path, "cannot tell the layout of a " + std::to_string(w) + "x" + std::to_string(h) +
                   " image (not 2:1 lat-long nor 1:6 cube, no envmap or rsibr.layout attribute); pass --layout");
}

EnvMap read_exr(const std::string& path, std::optional<LayoutKind> hint, EnvReadReport& report) {
  const ExrFileIn file(path);
  const ExrPartIn& h = file.parts().front();
  report.format = "exr";
  report.compression = h.compression;
  report.channels = h.channel_types;
  const bool rgb = h.has_channel("R") && h.has_channel("G") && h.has_channel("B");
  if (!rgb && !h.has_channel("Y")) refuse(path, "no R, G, B (or Y) channels; it has: " + report.channels);

  EnvMap map;
  if (rgb) {
    map.pixels = file.read(0, {"R", "G", "B"});
  } else {
    cv::cvtColor(file.read(0, {"Y"}), map.pixels, cv::COLOR_GRAY2RGB);
  }

  // Layout.
  LayoutKind kind;
  if (h.envmap != ExrEnvmap::None) {
    kind = h.envmap == ExrEnvmap::Cube ? LayoutKind::Cube : LayoutKind::LatLong;
    report.layout_source = "envmap attribute";
  } else if (const auto a = h.get<std::string>("rsibr.layout")) {
    try {
      kind = parse_layout_kind(*a);
    } catch (const std::exception& e) {
      refuse(path, e.what());
    }
    report.layout_source = "rsibr.layout attribute";
  } else if (hint) {
    kind = *hint;
    report.layout_source = "--layout";
    // rsibr writes non-square sphere maps with their layout attribute; a bare image said to be one
    // is a square crop of a mirror ball, or a mistake (a lat-long read as a ball).
    if (kind == LayoutKind::Sphere && h.width != h.height)
      refuse(path, "a " + std::to_string(h.width) + "x" + std::to_string(h.height) +
                       " image cannot be a mirror-ball (sphere) map: it must be square");
  } else {
    kind = layout_from_shape(path, h.width, h.height);
    report.layout_source = "shape";
  }
  try {
    map.layout = Layout(kind, h.width, h.height);
  } catch (const std::exception& e) {
    refuse(path, e.what());
  }

  // Colour: from the file's primaries to the working space.
  if (h.working_from_file) {
    const Eigen::Matrix3f m = h.working_from_file->cast<float>();
    map.pixels.forEach<cv::Vec3f>([&](cv::Vec3f& p, const int*) {
      const Eigen::Vector3f v = m * Eigen::Vector3f(p[0], p[1], p[2]);
      p = cv::Vec3f(v.x(), v.y(), v.z());
    });
    report.chromaticities_converted = true;
  }

  for (const auto& [key, value] : h.strings_with_prefix("rsibr."))
    if (key != "layout") map.attributes[key] = value;
  return map;
}

// The image size a Radiance .hdr header claims (its resolution line, "-Y H +X W" after the first
// empty line), checked before OpenCV allocates it: a hostile header must not size an allocation.
void check_hdr_size(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string line;
  for (int lines = 0; std::getline(in, line) && !line.empty(); ++lines)
    if (lines > 1000 || line.size() > 4096) refuse(path, "a Radiance header without its end");
  std::getline(in, line);
  std::istringstream res(line);
  std::string ay, ax;
  long long h = 0, w = 0;
  if (!(res >> ay >> h >> ax >> w) || ay.size() != 2 || ax.size() != 2 || (ay[1] != 'Y' && ay[1] != 'X'))
    refuse(path, "no Radiance resolution line (\"-Y H +X W\")");
  if (w < 1 || h < 1 || w > 65536 || h > 65536 || w * h > (1LL << 27))
    refuse(path, "a resolution of " + std::to_string(w) + "x" + std::to_string(h) + " (corrupt, or too large)");
}

EnvMap read_hdr(const std::string& path, std::optional<LayoutKind> hint, EnvReadReport& report) {
  check_hdr_size(path);
  cv::Mat bgr = read_image(path, cv::IMREAD_ANYDEPTH | cv::IMREAD_COLOR);
  if (bgr.empty()) refuse(path, "not a readable Radiance .hdr file");
  if (bgr.type() != CV_32FC3) bgr.convertTo(bgr, CV_32FC3);
  EnvMap map;
  cv::cvtColor(bgr, map.pixels, cv::COLOR_BGR2RGB);
  report.format = "hdr";
  report.channels = "RGBE";
  report.compression = "rle";
  const LayoutKind kind = hint ? *hint : layout_from_shape(path, bgr.cols, bgr.rows);
  report.layout_source = hint ? "--layout" : "shape";
  if (kind == LayoutKind::Sphere && bgr.cols != bgr.rows)
    refuse(path, "a " + std::to_string(bgr.cols) + "x" + std::to_string(bgr.rows) +
                     " image cannot be a mirror-ball (sphere) map: it must be square");
  try {
    map.layout = Layout(kind, bgr.cols, bgr.rows);
  } catch (const std::exception& e) {
    refuse(path, e.what());
  }
  return map;
}

}  // namespace

std::string fold_environment_ringing(EnvMap& env, const std::string& path, const EnvReadReport& report,
                                     bool already_folded) {
  if (report.texels.negative <= 0) return "";
  std::ostringstream line;
  line << path << ": " << report.texels.negative
       << " negative values (lossy-compression ringing) folded into their positive neighbours";
  if (already_folded) return line.str();
  const std::vector<double> before = integral(env);
  remove_negative_ringing(env.pixels);
  const std::vector<double> after = integral(env);
  double change = 0;
  for (std::size_t k = 0; k < before.size() && k < after.size(); ++k)
    change = std::max(change, std::abs(after[k] - before[k]) / std::max(1e-30, std::abs(before[k])));
  line << " (integral changed by " << std::setprecision(2) << 100 * change << "%)";
  return line.str();
}

EnvMap read_environment(const std::string& path, std::optional<LayoutKind> hint, EnvReadReport* report_out) {
  EnvReadReport report;
  require_regular_file(path);
  EnvMap map = with_file(path, [&] {
    if (looks_like_exr(path)) return read_exr(path, hint, report);
    if (lower_extension(path) == ".hdr" || lower_extension(path) == ".pic") return read_hdr(path, hint, report);
    refuse(path, "not an OpenEXR or Radiance .hdr file");
  });
  report.texels = audit_texels(map.pixels);
  if (report_out) *report_out = report;
  return map;
}

void write_environment(const std::string& path, const EnvMap& map, const ExrWriteOptions& options,
                       const ExrExtraChannels& extra_channels) {
  const int W = map.pixels.cols, H = map.pixels.rows, ch = map.pixels.channels();
  if (map.pixels.depth() != CV_32F || (ch != 1 && ch != 3 && ch != 4))
    refuse(path, "internal: pixels must be float with 1, 3 or 4 channels");
  if (W != map.layout.width() || H != map.layout.height()) refuse(path, "internal: pixels do not match the layout");
  ExrPartOut part;
  for (int k = 0; k < ch; ++k) part.channels.push_back({ch == 1 ? "Y" : std::string(1, "RGBA"[k]), map.pixels, k});
  for (const auto& [name, m] : extra_channels) {
    if (m.type() != CV_32FC1 || m.cols != W || m.rows != H)
      refuse(path, "internal: channel " + name + " must be float, one channel, of the map's size");
    part.channels.push_back({name, m, 0});
  }
  part.half = options.half;
  if (map.layout.kind() == LayoutKind::LatLong) part.envmap = ExrEnvmap::LatLong;
  if (map.layout.kind() == LayoutKind::Cube) part.envmap = ExrEnvmap::Cube;
  part.attributes.emplace_back("rsibr.layout", std::string(to_string(map.layout.kind())));
  for (const auto& [key, value] : map.attributes) part.attributes.emplace_back("rsibr." + key, value);
  write_exr(path, {part});
}

}  // namespace rsibr
