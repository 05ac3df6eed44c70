#include "cli/render_image.h"

#include "core/atomic_file.h"
#include "core/exr_io.h"
#include "core/map_set.h"
#include "core/text.h"

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfIntAttribute.h>
#include <OpenEXR/ImfMatrixAttribute.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfStandardAttributes.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <OpenEXR/ImfVecAttribute.h>

#include <cmath>
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
  return env;
}

namespace {
Imath::M33f m33(const Mat3& m) {
  Imath::M33f out;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) out[r][c] = float(m(r, c));  // m[row][col], as rsibr.worldFromView
  return out;
}
}  // namespace

void write_render_exr(const std::string& path, const cv::Mat& rgba_in, const Camera& cam,
                      const std::map<std::string, std::string>& strings, const std::map<std::string, int>& ints) {
  if (rgba_in.type() != CV_32FC4) throw std::logic_error("write_render_exr: the image must be CV_32FC4");
  const cv::Mat rgba = rgba_in.isContinuous() ? rgba_in : rgba_in.clone();
  const int W = rgba.cols, H = rgba.rows;
  Imf::Header header(W, H);
  header.compression() = Imf::ZIP_COMPRESSION;
  Imf::addChromaticities(header, Imf::Chromaticities());
  auto name = [](const std::string& key) {
    const std::string n = "rsibr." + key;
    if (n.size() > kMaxAttributeName) throw std::logic_error("attribute name '" + n + "' is too long");
    return n;
  };
  for (const auto& [key, value] : strings) header.insert(name(key), Imf::StringAttribute(valid_utf8(value)));
  for (const auto& [key, value] : ints) header.insert(name(key), Imf::IntAttribute(value));
  header.insert(name("eye"), Imf::V3fAttribute(Imath::V3f(float(cam.eye.x()), float(cam.eye.y()), float(cam.eye.z()))));
  header.insert(name("worldFromCam"), Imf::M33fAttribute(m33(cam.world_from_cam)));
  Mat3 K;
  K << cam.fx, 0, cam.cx, 0, cam.fy, cam.cy, 0, 0, 1;
  header.insert(name("intrinsics"), Imf::M33fAttribute(m33(K)));
  const char* names[] = {"R", "G", "B", "A"};
  Imf::FrameBuffer fb;
  char* base = reinterpret_cast<char*>(const_cast<float*>(rgba.ptr<float>()));
  for (int k = 0; k < 4; ++k) {
    header.channels().insert(names[k], Imf::Channel(Imf::FLOAT));
    fb.insert(names[k], Imf::Slice(Imf::FLOAT, base + k * sizeof(float), 4 * sizeof(float), 4 * sizeof(float) * std::size_t(W)));
  }
  try {
    write_atomically(path, [&](const std::string& tmp) {
      Imf::OutputFile out(tmp.c_str(), header);
      out.setFrameBuffer(fb);
      out.writePixels(H);
    });
  } catch (const std::exception& e) {
    throw std::runtime_error(path + ": " + e.what());
  }
}

}  // namespace rsibr::cli
