#include "formats/exr_file.h"

#include "formats/atomic_file.h"
#include "core/colour.h"
#include "formats/input_file.h"
#include "core/text.h"

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfThreading.h>
#include <OpenEXR/ImfChromaticitiesAttribute.h>
#include <OpenEXR/ImfCompression.h>
#include <OpenEXR/ImfEnvmapAttribute.h>
#include <OpenEXR/ImfFloatVectorAttribute.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputPart.h>
#include <OpenEXR/ImfIntAttribute.h>
#include <OpenEXR/ImfMatrixAttribute.h>
#include <OpenEXR/ImfMultiPartInputFile.h>
#include <OpenEXR/ImfMultiPartOutputFile.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfOutputPart.h>
#include <OpenEXR/ImfPartType.h>
#include <OpenEXR/ImfStandardAttributes.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <OpenEXR/ImfVecAttribute.h>
#include <Imath/half.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <mutex>
#include <sstream>
#include <thread>

namespace rsibr {

namespace {
// OpenEXR decodes and encodes a file's chunks on its own thread pool, sized here once to the
// machine (its default is none: one core for an 8K map's zip chunks).
void use_exr_threads() {
  static const bool started = [] {
    Imf::setGlobalThreadCount(int(std::max(1u, std::thread::hardware_concurrency())));
    return true;
  }();
  (void)started;
}
}  // namespace

namespace {

[[noreturn]] void fail(const std::string& path, const std::string& what) { throw FileError(path, what); }
[[noreturn]] void fail_output(const std::string& path, const std::string& what) {
  throw FileError(path, what, {}, FileRole::Output);
}

// Limits on what a header may claim before anything is allocated from it.
constexpr long long kMaxSide = 65536, kMaxPixels = 1LL << 27;

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

Imath::M33f to_m33(const Mat3& m) {
  Imath::M33f out;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) out[r][c] = float(m(r, c));
  return out;
}

Mat3 from_m33(const Imath::M33f& m) {
  Mat3 out;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) out(r, c) = m[r][c];
  return out;
}

// The size of a data window, checked to be one rsibr reads: at least 1 x 1, at most 65536 a side
// and 2^27 pixels (16384 x 8192; 1.6 GB of float RGB). A corrupt or hostile header must not size
// an allocation.
std::pair<int, int> checked_data_window(const Imath::Box2i& dw, const std::string& path) {
  const long long w = (long long)dw.max.x - dw.min.x + 1, h = (long long)dw.max.y - dw.min.y + 1;
  if (w < 1 || h < 1 || w > kMaxSide || h > kMaxSide || w * h > kMaxPixels)
    fail(path, "a data window of " + std::to_string(w) + "x" + std::to_string(h) + " pixels (corrupt, or too large)");
  return {int(w), int(h)};
}

// OpenEXR sizes its buffers from the header: a string attribute that claims 2 GB made OpenEXR 3.1
// allocate and clear 2 GB before it found the file was 3 KB (found by fuzz/fuzz_map_set), and a
// data window can claim any size. So the header's attributes are walked here first (each must fit
// in the file, names at most 255 bytes, at most 1024 attributes and 1024 parts), and OpenEXR's own
// sanity check is given limits (data windows at most 65536, tiles 8192 a side).
void check_before_opening(const std::string& path) {
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
  if (!in || head[0] != 0x76 || head[1] != 0x2f || head[2] != 0x31 || head[3] != 0x01)
    fail(path, "not an OpenEXR file");
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

ExrPartIn part_from_header(const Imf::Header& h, const std::string& path) {
  ExrPartIn p;
  if (h.hasName()) p.name = h.name();
  std::tie(p.width, p.height) = checked_data_window(h.dataWindow(), path);
  std::ostringstream types;
  for (auto it = h.channels().begin(); it != h.channels().end(); ++it) {
    p.channels.push_back(it.name());
    types << (it == h.channels().begin() ? "" : " ") << it.name() << ":" << pixel_type_name(it.channel().type);
  }
  p.channel_types = types.str();
  p.compression = compression_name(h.compression());
  if (Imf::hasEnvmap(h)) p.envmap = Imf::envmap(h) == Imf::ENVMAP_CUBE ? ExrEnvmap::Cube : ExrEnvmap::LatLong;
  if (Imf::hasChromaticities(h) && !same_chromaticities(Imf::chromaticities(h), Imf::Chromaticities()))
    p.working_from_file = working_from_chromaticities(Imf::chromaticities(h));
  for (auto it = h.begin(); it != h.end(); ++it) {
    const Imf::Attribute& a = it.attribute();
    if (const auto* s = dynamic_cast<const Imf::StringAttribute*>(&a))
      p.attributes[it.name()] = s->value();
    else if (const auto* i = dynamic_cast<const Imf::IntAttribute*>(&a))
      p.attributes[it.name()] = i->value();
    else if (const auto* v = dynamic_cast<const Imf::V3fAttribute*>(&a))
      p.attributes[it.name()] = Vec3(v->value().x, v->value().y, v->value().z);
    else if (const auto* m = dynamic_cast<const Imf::M33fAttribute*>(&a))
      p.attributes[it.name()] = from_m33(m->value());
    else if (const auto* f = dynamic_cast<const Imf::FloatVectorAttribute*>(&a))
      p.attributes[it.name()] = f->value();
  }
  return p;
}

Imf::Header header_for(const ExrPartOut& part, int W, int H, bool multipart, const std::string& path) {
  Imf::Header h(W, H);
  if (multipart || !part.name.empty()) h.setName(part.name);
  if (multipart) h.setType(Imf::SCANLINEIMAGE);
  h.compression() = part.compression == ExrCompression::Piz ? Imf::PIZ_COMPRESSION : Imf::ZIP_COMPRESSION;
  Imf::addChromaticities(h, Imf::Chromaticities());
  if (part.envmap == ExrEnvmap::LatLong) Imf::addEnvmap(h, Imf::ENVMAP_LATLONG);
  if (part.envmap == ExrEnvmap::Cube) Imf::addEnvmap(h, Imf::ENVMAP_CUBE);
  for (const auto& [name, value] : part.attributes) {
    if (name.size() > kMaxAttributeName)
      fail_output(path, "attribute name '" + name + "' is longer than 31 characters");
    if (const auto* s = std::get_if<std::string>(&value))
      h.insert(name, Imf::StringAttribute(valid_utf8(*s)));
    else if (const auto* i = std::get_if<int>(&value))
      h.insert(name, Imf::IntAttribute(*i));
    else if (const auto* v = std::get_if<Vec3>(&value))
      h.insert(name, Imf::V3fAttribute(Imath::V3f(float(v->x()), float(v->y()), float(v->z()))));
    else if (const auto* m = std::get_if<Mat3>(&value))
      h.insert(name, Imf::M33fAttribute(to_m33(*m)));
    else
      h.insert(name, Imf::FloatVectorAttribute(std::get<std::vector<float>>(value)));
  }
  const Imf::PixelType type = part.half ? Imf::HALF : Imf::FLOAT;
  for (const ExrChannelOut& c : part.channels) h.channels().insert(c.name, Imf::Channel(type));
  return h;
}

// The pixels of one part as OpenEXR slices: each channel copied to a plane of its stored type
// (float, or half after the range check), so any cv::Mat layout (strided, a ROI) is accepted.
struct PartPixels {
  std::vector<std::vector<float>> floats;
  std::vector<std::vector<Imath::half>> halves;
  Imf::FrameBuffer fb;
};

void fill_pixels(const ExrPartOut& part, int W, int H, const std::string& path, PartPixels& px) {
  for (const ExrChannelOut& c : part.channels) {
    std::vector<float> plane(std::size_t(W) * std::size_t(H));
    const int n = c.image.channels();
    for (int r = 0; r < H; ++r) {
      const float* row = c.image.ptr<float>(r);
      for (int x = 0; x < W; ++x) plane[std::size_t(r) * W + x] = row[std::size_t(x) * n + c.index];
    }
    if (!part.half) {
      px.floats.push_back(std::move(plane));
      px.fb.insert(c.name, Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(px.floats.back().data()), sizeof(float),
                                      sizeof(float) * std::size_t(W)));
      continue;
    }
    std::vector<Imath::half> h(plane.size());
    for (std::size_t i = 0; i < plane.size(); ++i) {
      if (std::isfinite(plane[i]) && std::abs(plane[i]) > 65504.f) {
        std::ostringstream msg;
        msg << "value " << plane[i] << " at pixel (" << i % W << ", " << i / W
            << ") exceeds the half-float range (65504); write float32 instead";
        fail_output(path, msg.str());
      }
      h[i] = Imath::half(plane[i]);
    }
    px.halves.push_back(std::move(h));
    px.fb.insert(c.name, Imf::Slice(Imf::HALF, reinterpret_cast<char*>(px.halves.back().data()), sizeof(Imath::half),
                                    sizeof(Imath::half) * std::size_t(W)));
  }
}

}  // namespace

bool looks_like_exr(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  unsigned char magic[4] = {0, 0, 0, 0};
  in.read(reinterpret_cast<char*>(magic), 4);
  return in.gcount() == 4 && magic[0] == 0x76 && magic[1] == 0x2f && magic[2] == 0x31 && magic[3] == 0x01;
}

bool ExrPartIn::has_channel(const std::string& c) const {
  for (const std::string& name : channels)
    if (name == c) return true;
  return false;
}

std::map<std::string, std::string> ExrPartIn::strings_with_prefix(const std::string& prefix) const {
  std::map<std::string, std::string> out;
  for (const auto& [name, value] : attributes)
    if (name.rfind(prefix, 0) == 0 && std::holds_alternative<std::string>(value))
      out[name.substr(prefix.size())] = std::get<std::string>(value);
  return out;
}

void write_exr(const std::string& path, const std::vector<ExrPartOut>& parts) {
  if (parts.empty()) fail_output(path, "internal: an EXR file needs at least one part");
  const bool multipart = parts.size() > 1;
  std::vector<Imf::Header> headers;
  std::vector<PartPixels> pixels(parts.size());
  for (std::size_t i = 0; i < parts.size(); ++i) {
    const ExrPartOut& part = parts[i];
    if (part.channels.empty()) fail_output(path, "internal: part " + std::to_string(i) + " has no channels");
    const cv::Size size = part.channels.front().image.size();
    for (const ExrChannelOut& c : part.channels)
      if (c.image.depth() != CV_32F || c.image.size() != size || c.index < 0 || c.index >= c.image.channels())
        fail_output(path, "internal: channel '" + c.name + "' is not a float channel of the part's size");
    if (multipart && part.name.empty())
      fail_output(path, "internal: part " + std::to_string(i) + " of several has no name");
    headers.push_back(header_for(part, size.width, size.height, multipart, path));
    fill_pixels(part, size.width, size.height, path, pixels[i]);
  }
  // OpenEXR wants the parts of one file to share their display window; each keeps its own data
  // window (its size), which is what readers take.
  for (Imf::Header& h : headers) h.displayWindow() = headers.front().displayWindow();
  std::string temporary;
  use_exr_threads();
  try {
    write_atomically(path, [&](const std::string& tmp) {
      temporary = tmp;
      if (!multipart) {
        Imf::OutputFile out(tmp.c_str(), headers.front());
        out.setFrameBuffer(pixels.front().fb);
        out.writePixels(parts.front().channels.front().image.rows);
        return;
      }
      Imf::MultiPartOutputFile file(tmp.c_str(), headers.data(), int(headers.size()));
      for (std::size_t i = 0; i < parts.size(); ++i) {
        Imf::OutputPart out(file, int(i));
        out.setFrameBuffer(pixels[i].fb);
        out.writePixels(parts[i].channels.front().image.rows);
      }
    });
  } catch (const std::exception& e) {
    // OpenEXR names the temporary, which never outlives the failure: the user is told `path`.
    std::string what = e.what();
    for (const std::string& name : {" \"" + temporary + "\"", " " + temporary})
      for (std::size_t at; !temporary.empty() && (at = what.find(name)) != std::string::npos;)
        what.erase(at, name.size());
    for (char& c : what)
      if (c == '\n') c = ' ';
    if (what.rfind(path + ": ", 0) == 0) what.erase(0, path.size() + 2);  // the file check names it already
    fail_output(path, what);
  }
}

bool exr_reads_back(const std::string& path) noexcept {
  try {
    use_exr_threads();
    Imf::MultiPartInputFile in(path.c_str());
    for (int p = 0; p < in.parts(); ++p) {
      if (!in.partComplete(p)) return false;
      const Imf::Header& h = in.header(p);
      if (h.hasType() && h.type() != Imf::SCANLINEIMAGE) continue;  // rsibr writes scan lines only
      const auto first = h.channels().begin();
      if (first == h.channels().end()) continue;
      // One channel into a scratch buffer is enough to make OpenEXR read and decode every chunk.
      const Imath::Box2i dw = h.dataWindow();
      const std::ptrdiff_t w = dw.max.x - dw.min.x + 1, rows = dw.max.y - dw.min.y + 1;
      std::vector<float> scratch(std::size_t(w * rows));
      char* origin = reinterpret_cast<char*>(scratch.data()) -
                     (std::ptrdiff_t(dw.min.x) + std::ptrdiff_t(dw.min.y) * w) * std::ptrdiff_t(sizeof(float));
      Imf::FrameBuffer fb;
      fb.insert(first.name(), Imf::Slice(Imf::FLOAT, origin, sizeof(float), sizeof(float) * std::size_t(w),
                                         first.channel().xSampling, first.channel().ySampling));
      Imf::InputPart part(in, p);
      part.setFrameBuffer(fb);
      part.readPixels(dw.min.y, dw.max.y);
    }
    return true;
  } catch (...) {
    return false;
  }
}

struct ExrFileIn::Impl {
  explicit Impl(const std::string& path) : file((use_exr_threads(), path.c_str())) {}
  Imf::MultiPartInputFile file;
};

ExrFileIn::ExrFileIn(const std::string& path) : path_(path) {
  with_file(path, [&] {
    require_regular_file(path);
    check_before_opening(path);
    impl_ = std::make_unique<Impl>(path);
    for (int i = 0; i < impl_->file.parts(); ++i) parts_.push_back(part_from_header(impl_->file.header(i), path));
    if (parts_.empty()) fail(path, "no parts");
  });
}

ExrFileIn::~ExrFileIn() = default;

cv::Mat ExrFileIn::read(int part, const std::vector<std::string>& channels) const {
  return with_file(path_, [&] {
    if (part < 0 || part >= int(parts_.size())) fail(path_, "internal: no part " + std::to_string(part));
    const ExrPartIn& p = parts_[std::size_t(part)];
    const int n = int(channels.size());
    if (n < 1 || n > CV_CN_MAX) fail(path_, "internal: read 1 to " + std::to_string(CV_CN_MAX) + " channels");
    for (std::size_t k = 0; k < channels.size(); ++k)
      for (std::size_t j = 0; j < k; ++j)
        if (channels[j] == channels[k]) fail(path_, "internal: channel " + channels[k] + " asked for twice");
    for (const std::string& c : channels)
      if (!p.has_channel(c)) {
        const std::string where = parts_.size() > 1 ? "part " + std::to_string(part) : "";
        throw FileError(path_, "no channel " + c + " (it has: " + p.channel_types + ")", where);
      }
    cv::Mat out(p.height, p.width, CV_32FC(n));
    const Imath::Box2i dw = impl_->file.header(part).dataWindow();
    const std::size_t xs = sizeof(float) * std::size_t(n), ys = xs * std::size_t(p.width);
    Imf::FrameBuffer fb;
    // Slice::Make offsets the base by the data window's origin, which may be anywhere.
    for (int k = 0; k < n; ++k)
      fb.insert(channels[std::size_t(k)],
                Imf::Slice::Make(Imf::FLOAT, out.ptr<char>() + k * sizeof(float), dw, xs, ys, 1, 1, 0.0));
    Imf::InputPart in(impl_->file, part);
    in.setFrameBuffer(fb);
    in.readPixels(dw.min.y, dw.max.y);
    return out;
  });
}

}  // namespace rsibr
