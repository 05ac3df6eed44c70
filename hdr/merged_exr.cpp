#include "hdr/merged_exr.h"

#include "core/atomic_file.h"
#include "core/exr_io.h"
#include "core/text.h"

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfStandardAttributes.h>
#include <OpenEXR/ImfStringAttribute.h>

#include <cmath>
#include <stdexcept>
#include <vector>

namespace rsibr {
namespace {

constexpr const char* kChannels[] = {"R", "G", "B", "variance.R", "variance.G", "variance.B", "clipped", "black", "ghost"};
constexpr int kCount = 9;

}  // namespace

void write_merged_exr(const std::string& path, const MergedImage& m, const std::map<std::string, std::string>& attributes) {
  const int W = m.radiance.cols, H = m.radiance.rows;
  auto fail = [&](const std::string& what) { throw std::runtime_error(path + ": " + what); };
  // Planar float buffer, one plane per channel.
  std::vector<float> planes(std::size_t(W) * H * kCount);
  const std::size_t plane = std::size_t(W) * H;
  for (int r = 0; r < H; ++r) {
    const float* rad = m.radiance.ptr<float>(r);
    const float* var = m.variance.ptr<float>(r);
    const unsigned char* f = m.flags.ptr<unsigned char>(r);
    for (int x = 0; x < W; ++x) {
      const std::size_t i = std::size_t(r) * W + x;
      for (int c = 0; c < 3; ++c) {
        if (!std::isfinite(rad[3 * x + c]) || !std::isfinite(var[3 * x + c]))
          fail("internal: non-finite value at pixel (" + std::to_string(x) + ", " + std::to_string(r) + ")");
        planes[std::size_t(c) * plane + i] = rad[3 * x + c];
        planes[std::size_t(3 + c) * plane + i] = var[3 * x + c];
      }
      planes[6 * plane + i] = (f[x] & kClipped) ? 1.f : 0.f;
      planes[7 * plane + i] = (f[x] & kBlack) ? 1.f : 0.f;
      planes[8 * plane + i] = (f[x] & kGhost) ? 1.f : 0.f;
    }
  }
  Imf::Header header(W, H);
  header.compression() = Imf::ZIP_COMPRESSION;
  Imf::addChromaticities(header, Imf::Chromaticities());
  for (const auto& [key, value] : attributes) {
    const std::string name = "rsibr." + key;
    if (name.size() > kMaxAttributeName) fail("attribute name '" + name + "' is longer than 31 characters");
    header.insert(name, Imf::StringAttribute(valid_utf8(value)));
  }
  Imf::FrameBuffer fb;
  for (int k = 0; k < kCount; ++k) {
    header.channels().insert(kChannels[k], Imf::Channel(Imf::FLOAT));
    fb.insert(kChannels[k], Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(planes.data() + std::size_t(k) * plane),
                                       sizeof(float), sizeof(float) * std::size_t(W)));
  }
  try {
    write_atomically(path, [&](const std::string& tmp) {
      Imf::OutputFile out(tmp.c_str(), header);
      out.setFrameBuffer(fb);
      out.writePixels(H);
    });
  } catch (const std::exception& e) {
    fail(e.what());
  }
}

MergedImage read_merged_exr(const std::string& path, std::map<std::string, std::string>* attributes) {
  try {
    check_exr_before_reading(path);
    Imf::InputFile in(path.c_str());
    const Imath::Box2i dw = in.header().dataWindow();
    const auto [W, H] = checked_data_window(dw, path);
    for (int k = 0; k < kCount; ++k)
      if (!in.header().channels().findChannel(kChannels[k]))
        throw std::runtime_error(std::string("no channel ") + kChannels[k] + " (not a merged view)");
    std::vector<float> planes(std::size_t(W) * H * kCount);
    const std::size_t plane = std::size_t(W) * H;
    Imf::FrameBuffer fb;
    for (int k = 0; k < kCount; ++k) {
      char* base = reinterpret_cast<char*>(planes.data() + std::size_t(k) * plane) -
                   (std::ptrdiff_t(dw.min.x) + std::ptrdiff_t(dw.min.y) * W) * std::ptrdiff_t(sizeof(float));
      fb.insert(kChannels[k], Imf::Slice(Imf::FLOAT, base, sizeof(float), sizeof(float) * std::size_t(W)));
    }
    in.setFrameBuffer(fb);
    in.readPixels(dw.min.y, dw.max.y);
    MergedImage m;
    m.radiance.create(H, W, CV_32FC3);
    m.variance.create(H, W, CV_32FC3);
    m.flags.create(H, W, CV_8UC1);
    for (int r = 0; r < H; ++r)
      for (int x = 0; x < W; ++x) {
        const std::size_t i = std::size_t(r) * W + x;
        for (int c = 0; c < 3; ++c) {
          m.radiance.ptr<float>(r)[3 * x + c] = planes[std::size_t(c) * plane + i];
          m.variance.ptr<float>(r)[3 * x + c] = planes[std::size_t(3 + c) * plane + i];
        }
        unsigned char f = 0;
        if (planes[6 * plane + i] > 0.5f) f |= kClipped, ++m.clipped;
        if (planes[7 * plane + i] > 0.5f) f |= kBlack, ++m.black;
        if (planes[8 * plane + i] > 0.5f) f |= kGhost, ++m.ghost;
        m.flags.ptr<unsigned char>(r)[x] = f;
      }
    if (attributes)
      for (auto it = in.header().begin(); it != in.header().end(); ++it)
        if (const auto* s = dynamic_cast<const Imf::StringAttribute*>(&it.attribute());
            s && std::string(it.name()).rfind("rsibr.", 0) == 0)
          (*attributes)[std::string(it.name()).substr(6)] = s->value();
    return m;
  } catch (const std::exception& e) {
    throw std::runtime_error(path + ": " + e.what());
  }
}

}  // namespace rsibr
