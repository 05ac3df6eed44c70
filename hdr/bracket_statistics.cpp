#include "hdr/bracket_statistics.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace rsibr {

BracketStatistics::BracketStatistics(int expected_views, int candidates, int noise_pixels)
    : expected_views_(std::max(1, expected_views)), candidates_(candidates), noise_pixels_(noise_pixels) {}

void BracketStatistics::add(const BracketSet& b) {
  if (b.size() == 0) return;
  if (max_code == 0) {
    max_code = b.max_code;
    shift = max_code > 255 ? 8 : 0;
    bins = (max_code >> shift) + 1;
    for (auto& h : pair_histogram) h.assign(std::size_t(bins) * std::size_t(bins), 0);
  } else if (b.max_code != max_code) {
    throw std::runtime_error("views of different bit depths (" + std::to_string(max_code == 255 ? 8 : 16) + " and " +
                             std::to_string(b.max_code == 255 ? 8 : 16) + " bits)");
  }
  lossy = lossy || b.lossy;
  if (b.size() < 2) {
    ++single_bracket_views;
    return;
  }
  const int P = int(b.size()), H = b.rows(), W = b.cols();
  // A pixel the file says is saturated (RAW) counts as the top code in every channel, so the
  // saturation rule of recovery and noise estimation leaves it out as the merge does.
  auto file_saturated = [&](int j, int r, int c) {
    return std::size_t(j) < b.saturated.size() && !b.saturated[std::size_t(j)].empty() &&
           b.saturated[std::size_t(j)].at<unsigned char>(r, c) != 0;
  };
  // Pixels some bracket does not cover (padding, a shifted edge) are no evidence.
  auto covered_by_all = [&](int r, int c) {
    for (const cv::Mat& m : b.covered)
      if (!m.empty() && m.at<unsigned char>(r, c) == 0) return false;
    return true;
  };
  ViewStatistics v;
  v.exposures = b.exposures;
  v.brackets = P;
  // Sample candidates (2 px clear of the border for the 5x5 patch).
  const double want = std::max(10000.0, double(candidates_) / expected_views_);
  const int stride = std::max(1, int(std::sqrt(double(H) * W / want)));
  const int border = 2;
  for (int r = border + stride / 2; r < H - border; r += stride)
    for (int c = border + stride / 2; c < W - border; c += stride) {
      if (!covered_by_all(r, c)) continue;
      for (int j = 0; j < P; ++j) {
        const cv::Mat& img = b.codes[std::size_t(j)];
        const auto z = img.at<cv::Vec3w>(r, c);
        const bool top = file_saturated(j, r, c);
        for (int ch = 0; ch < 3; ++ch) v.sample_codes.push_back(top ? std::uint16_t(max_code) : z[ch]);
        double sum[3] = {0, 0, 0}, sq[3] = {0, 0, 0};
        for (int dr = -2; dr <= 2; ++dr) {
          const auto* p = img.ptr<std::uint16_t>(r + dr) + 3 * (c - 2);
          for (int dc = 0; dc < 5; ++dc)
            for (int ch = 0; ch < 3; ++ch) sum[ch] += p[3 * dc + ch], sq[ch] += double(p[3 * dc + ch]) * p[3 * dc + ch];
        }
        double rough = 0;
        for (int ch = 0; ch < 3; ++ch) {
          const double m = sum[ch] / 25;
          rough += std::sqrt(std::max(0.0, sq[ch] / 25 - m * m)) / 3;
        }
        v.sample_roughness.push_back(float(rough / max_code));
      }
    }
  // Noise pixels.
  const double want_noise = std::max(20000.0, double(noise_pixels_) / expected_views_);
  const int ns = std::max(1, int(std::sqrt(double(H) * W / want_noise)));
  for (int r = 0; r < H; r += ns)
    for (int c = 0; c < W; c += ns) {
      if (!covered_by_all(r, c)) continue;
      for (int j = 0; j < P; ++j) {
        const auto* z = b.codes[std::size_t(j)].ptr<std::uint16_t>(r) + 3 * c;
        const bool top = file_saturated(j, r, c);
        for (int ch = 0; ch < 3; ++ch) {
          v.noise_codes.push_back(top ? std::uint16_t(max_code) : z[ch]);
          v.noise_activity.push_back(code_activity(b.codes[std::size_t(j)], r, c, ch));
        }
      }
    }
  // Pair histograms (every pixel of a sparse grid).
  const int hs = std::max(1, int(std::sqrt(double(H) * W / 250000.0)));
  for (int j = 0; j + 1 < P; ++j) {
    int k = j + 1;
    while (k < P && b.exposures[std::size_t(k)] < 1.5 * b.exposures[std::size_t(j)]) ++k;
    if (k == P) continue;
    for (int r = 0; r < H; r += hs) {
      const auto* zj = b.codes[std::size_t(j)].ptr<std::uint16_t>(r);
      const auto* zk = b.codes[std::size_t(k)].ptr<std::uint16_t>(r);
      for (int c = 0; c < W; c += hs)
        for (int ch = 0; ch < 3; ++ch)
          ++pair_histogram[std::size_t(ch)][std::size_t(zj[3 * c + ch] >> shift) * std::size_t(bins) +
                                            std::size_t(zk[3 * c + ch] >> shift)];
    }
  }
  views.push_back(std::move(v));
}

}  // namespace rsibr
