#include "core/exr_io.h"

#include "core/atomic_file.h"
#include "core/colour.h"
#include "core/input_file.h"
#include "core/text.h"

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfChromaticitiesAttribute.h>
#include <OpenEXR/ImfEnvmapAttribute.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfStandardAttributes.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <OpenEXR/ImfCompression.h>
#include <Imath/half.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <sstream>
#include <stdexcept>

namespace rsibr {
namespace {

[[noreturn]] void fail(const std::string& path, const std::string& what) {
  throw std::runtime_error(path + ": " + what);
}

const char* pixel_type_name(Imf::PixelType t) {
  switch (t) {
    case Imf::UINT: return "uint";
    case Imf::HALF: return "half";
    case Imf::FLOAT: return "float";
    default: return "?";
  }
}

std::string compression_name(Imf::Compression c) {
  switch (c) {
    case Imf::NO_COMPRESSION: return "none";
    case Imf::RLE_COMPRESSION: return "rle";
    case Imf::ZIPS_COMPRESSION: return "zips";
    case Imf::ZIP_COMPRESSION: return "zip";
    case Imf::PIZ_COMPRESSION: return "piz";
    case Imf::PXR24_COMPRESSION: return "pxr24 (lossy)";
    case Imf::B44_COMPRESSION: return "b44 (lossy)";
    case Imf::B44A_COMPRESSION: return "b44a (lossy)";
    case Imf::DWAA_COMPRESSION: return "dwaa (lossy)";
    case Imf::DWAB_COMPRESSION: return "dwab (lossy)";
    default: return "unknown";
  }
}

bool same_chromaticities(const Imf::Chromaticities& a, const Imf::Chromaticities& b) {
  auto close = [](const Imath::V2f& p, const Imath::V2f& q) { return (p - q).length() < 1e-4f; };
  return close(a.red, b.red) && close(a.green, b.green) && close(a.blue, b.blue) && close(a.white, b.white);
}

LayoutKind layout_from_shape(const std::string& path, int w, int h) {
  if (w == 2 * h) return LayoutKind::LatLong;
  if (h == 6 * w) return LayoutKind::Cube;
  fail(path, "cannot tell the layout of a " + std::to_string(w) + "x" + std::to_string(h) +
                 " image (not 2:1 lat-long nor 1:6 cube, no envmap or rsibr.layout attribute); pass --layout");
}

EnvMap read_exr(const std::string& path, std::optional<LayoutKind> hint, EnvReadReport& report) {
  check_exr_before_reading(path);
  Imf::InputFile file(path.c_str());
  const Imf::Header& h = file.header();
  const Imath::Box2i dw = h.dataWindow();
  const auto [W, H] = checked_data_window(dw, path);
  report.format = "exr";
  report.compression = compression_name(h.compression());

  const Imf::ChannelList& chans = h.channels();
  std::ostringstream names;
  for (auto it = chans.begin(); it != chans.end(); ++it)
    names << (it == chans.begin() ? "" : " ") << it.name() << ":" << pixel_type_name(it.channel().type);
  report.channels = names.str();
  const bool rgb = chans.findChannel("R") && chans.findChannel("G") && chans.findChannel("B");
  const bool luminance = chans.findChannel("Y") != nullptr;
  if (!rgb && !luminance) fail(path, "no R, G, B (or Y) channels; it has: " + report.channels);

  EnvMap map;
  map.pixels = cv::Mat(H, W, CV_32FC3);
  Imf::FrameBuffer fb;
  char* base = reinterpret_cast<char*>(map.pixels.ptr<float>());
  const std::size_t xs = 3 * sizeof(float), ys = xs * std::size_t(W);
  const char* chan_names[3] = {"R", "G", "B"};
  // A FrameBuffer holds one slice per channel name: a luminance-only file is read into R, then
  // copied to G and B.
  for (int k = 0; k < (rgb ? 3 : 1); ++k)
    fb.insert(rgb ? chan_names[k] : "Y",
              Imf::Slice::Make(Imf::FLOAT, base + k * sizeof(float), dw, xs, ys, 1, 1, 0.0));
  file.setFrameBuffer(fb);
  file.readPixels(dw.min.y, dw.max.y);
  if (!rgb) map.pixels.forEach<cv::Vec3f>([](cv::Vec3f& p, const int*) { p[1] = p[2] = p[0]; });

  // Layout.
  LayoutKind kind;
  if (Imf::hasEnvmap(h)) {
    kind = Imf::envmap(h) == Imf::ENVMAP_CUBE ? LayoutKind::Cube : LayoutKind::LatLong;
    report.layout_source = "envmap attribute";
  } else if (const auto* a = h.findTypedAttribute<Imf::StringAttribute>("rsibr.layout")) {
    try {
      kind = parse_layout_kind(a->value());
    } catch (const std::exception& e) {
      fail(path, e.what());
    }
    report.layout_source = "rsibr.layout attribute";
  } else if (hint) {
    kind = *hint;
    report.layout_source = "--layout";
  } else {
    kind = layout_from_shape(path, W, H);
    report.layout_source = "shape";
  }
  try {
    map.layout = Layout(kind, W, H);
  } catch (const std::exception& e) {
    fail(path, e.what());
  }

  // Colour: from the file's primaries to the working space.
  if (Imf::hasChromaticities(h) && !same_chromaticities(Imf::chromaticities(h), Imf::Chromaticities())) {
    const Eigen::Matrix3f m = working_from_chromaticities(Imf::chromaticities(h)).cast<float>();
    map.pixels.forEach<cv::Vec3f>([&](cv::Vec3f& p, const int*) {
      const Eigen::Vector3f v = m * Eigen::Vector3f(p[0], p[1], p[2]);
      p = cv::Vec3f(v.x(), v.y(), v.z());
    });
    report.chromaticities_converted = true;
  }

  for (auto it = h.begin(); it != h.end(); ++it) {
    const std::string name = it.name();
    if (name.rfind("rsibr.", 0) != 0 || name == "rsibr.layout") continue;
    if (const auto* s = dynamic_cast<const Imf::StringAttribute*>(&it.attribute()))
      map.attributes[name.substr(6)] = s->value();
  }
  return map;
}

// The image size a Radiance .hdr header claims (its resolution line, "-Y H +X W" after the first
// empty line), checked before OpenCV allocates it: a hostile header must not size an allocation.
void check_hdr_size(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::string line;
  for (int lines = 0; std::getline(in, line) && !line.empty(); ++lines)
    if (lines > 1000 || line.size() > 4096) fail(path, "a Radiance header without its end");
  std::getline(in, line);
  std::istringstream res(line);
  std::string ay, ax;
  long long h = 0, w = 0;
  if (!(res >> ay >> h >> ax >> w) || ay.size() != 2 || ax.size() != 2 || (ay[1] != 'Y' && ay[1] != 'X'))
    fail(path, "no Radiance resolution line (\"-Y H +X W\")");
  if (w < 1 || h < 1 || w > 65536 || h > 65536 || w * h > (1LL << 27))
    fail(path, "a resolution of " + std::to_string(w) + "x" + std::to_string(h) + " (corrupt, or too large)");
}

EnvMap read_hdr(const std::string& path, std::optional<LayoutKind> hint, EnvReadReport& report) {
  check_hdr_size(path);
  cv::Mat bgr = cv::imread(path, cv::IMREAD_ANYDEPTH | cv::IMREAD_COLOR);
  if (bgr.empty()) fail(path, "not a readable Radiance .hdr file");
  if (bgr.type() != CV_32FC3) bgr.convertTo(bgr, CV_32FC3);
  EnvMap map;
  cv::cvtColor(bgr, map.pixels, cv::COLOR_BGR2RGB);
  report.format = "hdr";
  report.channels = "RGBE";
  report.compression = "rle";
  const LayoutKind kind = hint ? *hint : layout_from_shape(path, bgr.cols, bgr.rows);
  report.layout_source = hint ? "--layout" : "shape";
  try {
    map.layout = Layout(kind, bgr.cols, bgr.rows);
  } catch (const std::exception& e) {
    fail(path, e.what());
  }
  return map;
}

}  // namespace

std::pair<int, int> checked_data_window(const Imath::Box2i& dw, const std::string& path) {
  const long long w = (long long)dw.max.x - dw.min.x + 1, h = (long long)dw.max.y - dw.min.y + 1;
  if (w < 1 || h < 1 || w > 65536 || h > 65536 || w * h > (1LL << 27))
    fail(path, "a data window of " + std::to_string(w) + "x" + std::to_string(h) + " pixels (corrupt, or too large)");
  return {int(w), int(h)};
}

void check_exr_before_reading(const std::string& path) {
  static std::once_flag once;
  std::call_once(once, [] {
    Imf::Header::setMaxImageSize(65536, 65536);
    Imf::Header::setMaxTileSize(8192, 8192);
  });
  //   file   := magic(4) version(4) header+ [0]        (one header, or several ended by an empty one)
  //   header := attribute* 0;  attribute := name 0 type 0 size(int32 LE) value(size bytes)
  std::ifstream in(path, std::ios::binary);
  in.seekg(0, std::ios::end);
  const long long file_size = in.tellg();
  in.seekg(0);
  unsigned char head[8] = {};
  in.read(reinterpret_cast<char*>(head), 8);
  if (!in || head[0] != 0x76 || head[1] != 0x2f || head[2] != 0x31 || head[3] != 0x01) fail(path, "not an OpenEXR file");
  const bool multipart = (head[5] & 0x10) != 0;
  auto read_string = [&](const char* what) {
    std::string s;
    for (char c; in.get(c) && c != '\0';) {
      s += c;
      if (s.size() > 255) fail(path, std::string("a header ") + what + " longer than 255 bytes");
    }
    if (!in) fail(path, "the header ends before the pixels (truncated?)");
    return s;
  };
  for (int part = 0;; ++part) {
    if (part >= 1024) fail(path, "more than 1024 parts");
    int attributes = 0;
    for (;; ++attributes) {
      if (attributes > 1024) fail(path, "more than 1024 header attributes");
      const std::string name = read_string("attribute name");
      if (name.empty()) break;
      read_string("type name");
      unsigned char b[4];
      in.read(reinterpret_cast<char*>(b), 4);
      const long long size = std::int32_t(std::uint32_t(b[0]) | std::uint32_t(b[1]) << 8 | std::uint32_t(b[2]) << 16 |
                                          std::uint32_t(b[3]) << 24);
      if (!in || size < 0 || size > file_size - (long long)in.tellg())
        fail(path, "header attribute '" + quoted_for_message(name) + "' claims " + std::to_string(size) +
                       " bytes, more than the file holds (corrupt or truncated)");
      in.seekg(size, std::ios::cur);
    }
    if (!multipart) break;
    if (attributes == 0) break;  // the empty header that ends a multi-part file's headers
  }
}

EnvMap read_environment(const std::string& path, std::optional<LayoutKind> hint, EnvReadReport* report_out) {
  EnvReadReport report;
  try {
    require_regular_file(path);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(e.what());  // this reader's errors are runtime_error, whatever the cause
  }
  std::ifstream probe(path, std::ios::binary);
  unsigned char magic[4] = {0, 0, 0, 0};
  probe.read(reinterpret_cast<char*>(magic), 4);
  const bool is_exr = probe.gcount() == 4 && magic[0] == 0x76 && magic[1] == 0x2f && magic[2] == 0x31 && magic[3] == 0x01;
  probe.close();

  EnvMap map;
  try {
    if (is_exr) {
      map = read_exr(path, hint, report);
    } else if (lower_extension(path) == ".hdr" || lower_extension(path) == ".pic") {
      map = read_hdr(path, hint, report);
    } else {
      fail(path, "not an OpenEXR or Radiance .hdr file");
    }
  } catch (const std::exception& e) {
    std::string msg = e.what();
    if (msg.rfind(path + ":", 0) == 0) throw;
    // OpenEXR's own exceptions (Iex::BaseExc) derive from std::exception only, not
    // std::runtime_error; keep the message on one line.
    std::replace(msg.begin(), msg.end(), '\n', ' ');
    fail(path, msg);
  }
  report.texels = audit_texels(map.pixels);
  if (report_out) *report_out = report;
  return map;
}

void write_environment(const std::string& path, const EnvMap& map, const ExrWriteOptions& options) {
  const int W = map.pixels.cols, H = map.pixels.rows, ch = map.pixels.channels();
  if (map.pixels.depth() != CV_32F || (ch != 1 && ch != 3 && ch != 4))
    fail(path, "internal: pixels must be float with 1, 3 or 4 channels");
  if (W != map.layout.width() || H != map.layout.height()) fail(path, "internal: pixels do not match the layout");

  Imf::Header header(W, H);
  header.compression() = Imf::ZIP_COMPRESSION;
  Imf::addChromaticities(header, Imf::Chromaticities());
  if (map.layout.kind() == LayoutKind::LatLong) Imf::addEnvmap(header, Imf::ENVMAP_LATLONG);
  if (map.layout.kind() == LayoutKind::Cube) Imf::addEnvmap(header, Imf::ENVMAP_CUBE);
  header.insert("rsibr.layout", Imf::StringAttribute(to_string(map.layout.kind())));
  for (const auto& [key, value] : map.attributes) {
    const std::string name = "rsibr." + key;
    if (name.size() > kMaxAttributeName) fail(path, "attribute name '" + name + "' is longer than 31 characters");
    header.insert(name, Imf::StringAttribute(valid_utf8(value)));
  }

  const char* names1[] = {"Y"};
  const char* names3[] = {"R", "G", "B", "A"};
  const char** names = ch == 1 ? names1 : names3;
  const Imf::PixelType type = options.half ? Imf::HALF : Imf::FLOAT;
  for (int k = 0; k < ch; ++k) header.channels().insert(names[k], Imf::Channel(type));

  // Interleaved source buffer for the slices: converted halves, or the float pixels themselves.
  std::vector<Imath::half> halves;
  cv::Mat contiguous = map.pixels.isContinuous() ? map.pixels : map.pixels.clone();
  char* base = reinterpret_cast<char*>(contiguous.data);
  std::size_t elem = sizeof(float);
  if (options.half) {
    halves.resize(std::size_t(W) * H * ch);
    const float* p = contiguous.ptr<float>();
    for (std::size_t i = 0; i < halves.size(); ++i) {
      if (std::isfinite(p[i]) && std::abs(p[i]) > 65504.f) {
        std::ostringstream msg;
        msg << "value " << p[i] << " at pixel (" << (i / ch) % W << ", " << i / ch / W
            << ") exceeds the half-float range (65504); write float32 instead";
        fail(path, msg.str());
      }
      halves[i] = Imath::half(p[i]);
    }
    base = reinterpret_cast<char*>(halves.data());
    elem = sizeof(Imath::half);
  }
  Imf::FrameBuffer fb;
  for (int k = 0; k < ch; ++k)
    fb.insert(names[k], Imf::Slice(type, base + k * elem, ch * elem, ch * elem * std::size_t(W)));
  std::string temporary;
  try {
    write_atomically(path, [&](const std::string& tmp) {
      temporary = tmp;
      Imf::OutputFile out(tmp.c_str(), header);
      out.setFrameBuffer(fb);
      out.writePixels(H);
    });
  } catch (const std::exception& e) {
    // OpenEXR names the temporary, which never outlives the failure: the user is told `path`.
    std::string what = e.what();
    for (const std::string& name : {" \"" + temporary + "\"", " " + temporary})
      for (std::size_t at; !temporary.empty() && (at = what.find(name)) != std::string::npos;) what.erase(at, name.size());
    fail(path, what);
  }
}

}  // namespace rsibr
