#include "hdr/merged_exr.h"

#include <cmath>

namespace rsibr {
namespace {

const std::vector<std::string> kRadiance = {"R", "G", "B"};
const std::vector<std::string> kVariance = {"variance.R", "variance.G", "variance.B"};
const std::vector<std::string> kFlags = {"clipped", "black", "ghost"};

}  // namespace

void write_merged_exr(const std::string& path, const MergedImage& m,
                      const std::map<std::string, std::string>& attributes) {
  const int W = m.radiance.cols, H = m.radiance.rows;
  for (const cv::Mat* image : {&m.radiance, &m.variance})
    for (int r = 0; r < H; ++r) {
      const float* p = image->ptr<float>(r);
      for (int x = 0; x < 3 * W; ++x)
        if (!std::isfinite(p[x]))
          throw FileError(
              path, "internal: non-finite value at pixel (" + std::to_string(x / 3) + ", " + std::to_string(r) + ")",
              {}, FileRole::Output);
    }
  // The flag bits as 0/1 planes, one channel each.
  cv::Mat flags(H, W, CV_32FC3);
  for (int r = 0; r < H; ++r) {
    const unsigned char* f = m.flags.ptr<unsigned char>(r);
    float* out = flags.ptr<float>(r);
    for (int x = 0; x < W; ++x) {
      out[3 * x] = (f[x] & kClipped) ? 1.f : 0.f;
      out[3 * x + 1] = (f[x] & kBlack) ? 1.f : 0.f;
      out[3 * x + 2] = (f[x] & kGhost) ? 1.f : 0.f;
    }
  }
  ExrPartOut part;
  part.compression = ExrCompression::Piz;  // lossless, and half ZIP's write time on merged views
  for (int k = 0; k < 3; ++k) {
    part.channels.push_back({kRadiance[std::size_t(k)], m.radiance, k});
    part.channels.push_back({kVariance[std::size_t(k)], m.variance, k});
    part.channels.push_back({kFlags[std::size_t(k)], flags, k});
  }
  for (const auto& [key, value] : attributes) part.attributes.emplace_back("rsibr." + key, value);
  write_exr(path, {part});
}

bool is_merged_view(const ExrPartIn& part) {
  for (const auto* names : {&kRadiance, &kVariance, &kFlags})
    for (const std::string& c : *names)
      if (!part.has_channel(c)) return false;
  return true;
}

MergedImage read_merged_exr(const std::string& path, std::map<std::string, std::string>* attributes) {
  return read_merged_exr(ExrFileIn(path), attributes);
}

MergedImage read_merged_exr(const ExrFileIn& file, std::map<std::string, std::string>* attributes, bool variance) {
  const ExrPartIn& h = file.parts().front();
  for (const auto* names : {&kRadiance, &kVariance, &kFlags})
    for (const std::string& c : *names)
      if (!h.has_channel(c)) throw FileError(file.path(), "no channel " + c + " (not a merged view)");
  // One read of the channels wanted (the file is decoded once), then split: R, G, B, [variance,]
  // flags.
  std::vector<std::string> all = kRadiance;
  if (variance) all.insert(all.end(), kVariance.begin(), kVariance.end());
  all.insert(all.end(), kFlags.begin(), kFlags.end());
  const cv::Mat px = file.read(0, all);
  const int n = int(all.size()), f0 = variance ? 6 : 3;
  MergedImage m;
  m.radiance.create(h.height, h.width, CV_32FC3);
  if (variance) m.variance.create(h.height, h.width, CV_32FC3);
  m.flags.create(h.height, h.width, CV_8UC1);
  for (int r = 0; r < h.height; ++r) {
    const float* p = px.ptr<float>(r);
    float* rad = m.radiance.ptr<float>(r);
    float* var = variance ? m.variance.ptr<float>(r) : nullptr;
    unsigned char* out = m.flags.ptr<unsigned char>(r);
    for (int x = 0; x < h.width; ++x, p += n) {
      for (int c = 0; c < 3; ++c) rad[3 * x + c] = p[c];
      if (var)
        for (int c = 0; c < 3; ++c) var[3 * x + c] = p[3 + c];
      unsigned char f = 0;
      if (p[f0] > 0.5f) f |= kClipped, ++m.clipped;
      if (p[f0 + 1] > 0.5f) f |= kBlack, ++m.black;
      if (p[f0 + 2] > 0.5f) f |= kGhost, ++m.ghost;
      out[x] = f;
    }
  }
  if (attributes)
    for (const auto& [key, value] : h.strings_with_prefix("rsibr.")) (*attributes)[key] = value;
  return m;
}

}  // namespace rsibr
