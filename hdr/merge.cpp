#include "hdr/merge.h"

#include "core/parallel.h"
#include "hdr/response_recovery.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace rsibr {

MergedImage merge_brackets(const BracketSet& b, const ResponseCurve& curve, const NoiseModel& noise,
                           const MergeOptions& o) {
  if (curve.max_code != b.max_code)
    throw std::invalid_argument("the response curve is for " + std::to_string(curve.max_code) +
                                "-code input, the brackets have codes up to " + std::to_string(b.max_code));
  constexpr int kMax = 32;
  const int P = int(b.size());
  if (P < 1 || P > kMax) throw std::invalid_argument("between 1 and 32 brackets per view");
  const int sat = o.saturation_code > 0 ? o.saturation_code : default_saturation_code(b.max_code);
  std::array<std::vector<float>, 3> tx, tq;
  curve.tables(tx, tq);
  float inv_e[kMax], e[kMax];
  for (int j = 0; j < P; ++j) e[j] = float(b.exposures[std::size_t(j)]), inv_e[j] = float(1.0 / b.exposures[std::size_t(j)]);
  float shot[3], read[3];
  for (int c = 0; c < 3; ++c) shot[c] = float(noise.shot[std::size_t(c)]), read[c] = float(noise.read[std::size_t(c)]);
  const float eps2 = float(o.model_error * o.model_error);
  const int H = b.rows(), W = b.cols();
  MergedImage m;
  m.radiance.create(H, W, CV_32FC3);
  m.variance.create(H, W, CV_32FC3);
  m.flags.create(H, W, CV_8UC1);
  std::vector<long> counts(std::size_t(H) * 3, 0);
  parallel_for_rows(H, [&](int r) {
    const std::uint16_t* row[kMax];
    for (int j = 0; j < P; ++j) row[j] = b.codes[std::size_t(j)].ptr<std::uint16_t>(r);
    float* out = m.radiance.ptr<float>(r);
    float* var = m.variance.ptr<float>(r);
    unsigned char* flag = m.flags.ptr<unsigned char>(r);
    for (int x = 0; x < W; ++x) {
      // Brackets usable for this pixel: no channel saturated.
      int used[kMax];
      int n = 0;
      for (int j = 0; j < P; ++j) {
        const std::uint16_t* z = row[j] + 3 * x;
        if (z[0] < sat && z[1] < sat && z[2] < sat) used[n++] = j;
      }
      unsigned char f = 0;
      {
        const std::uint16_t* z = row[P - 1] + 3 * x;
        if (z[0] == 0 && z[1] == 0 && z[2] == 0) f |= kBlack;
      }
      if (n == 0) {
        // Saturated in every bracket: the shortest bracket's value, a lower bound.
        f |= kClipped;
        const std::uint16_t* z = row[0] + 3 * x;
        for (int c = 0; c < 3; ++c) {
          const float X = tx[std::size_t(c)][z[c]];
          out[3 * x + c] = X * inv_e[0];
          var[3 * x + c] = (shot[c] * X + read[c] + tq[std::size_t(c)][z[c]]) * inv_e[0] * inv_e[0];
        }
        flag[x] = f;
        continue;
      }
      float chi2 = 0;
      for (int c = 0; c < 3; ++c) {
        const float* xt = tx[std::size_t(c)].data();
        const float* qt = tq[std::size_t(c)].data();
        float Xs[kMax], base[kMax];
        // Pass 1: weights from the measured signal.
        float sw = 0, swl = 0;
        for (int k = 0; k < n; ++k) {
          const int j = used[k];
          const int z = row[j][3 * x + c];
          Xs[k] = xt[z];
          base[k] = read[c] + qt[z];
          const float w = e[j] * e[j] / (shot[c] * Xs[k] + base[k]);
          sw += w, swl += w * Xs[k] * inv_e[j];
        }
        float L = swl / sw;
        if (o.pilot_pass) {
          // Pass 2: weights from the pilot radiance.
          const float Lp = std::max(L, 0.f);
          sw = 0, swl = 0;
          for (int k = 0; k < n; ++k) {
            const int j = used[k];
            const float w = e[j] * e[j] / (shot[c] * Lp * e[j] + base[k]);
            sw += w, swl += w * Xs[k] * inv_e[j];
          }
          L = swl / sw;
        }
        out[3 * x + c] = L;
        var[3 * x + c] = 1.f / sw;
        if (n > 1) {
          const float Lp = std::max(L, 0.f);
          for (int k = 0; k < n; ++k) {
            const int j = used[k];
            const float d = Xs[k] * inv_e[j] - L;
            const float v = (shot[c] * Lp * e[j] + base[k]) * inv_e[j] * inv_e[j] + eps2 * Lp * Lp;
            chi2 += d * d / v;
          }
        }
      }
      if (n > 1) {
        const float dof = 3.f * float(n - 1);
        if (chi2 > dof + float(o.ghost_sigmas) * std::sqrt(2.f * dof)) f |= kGhost;
      }
      flag[x] = f;
    }
    long* cnt = &counts[std::size_t(r) * 3];
    for (int x = 0; x < W; ++x) {
      cnt[0] += (flag[x] & kClipped) != 0;
      cnt[1] += (flag[x] & kBlack) != 0;
      cnt[2] += (flag[x] & kGhost) != 0;
    }
  });
  for (int r = 0; r < H; ++r) {
    m.clipped += counts[std::size_t(r) * 3];
    m.black += counts[std::size_t(r) * 3 + 1];
    m.ghost += counts[std::size_t(r) * 3 + 2];
  }
  return m;
}

cv::Mat merge_hat_weighted(const BracketSet& b, const ResponseCurve& curve, int saturation_code) {
  const int sat = saturation_code > 0 ? saturation_code : default_saturation_code(b.max_code);
  std::array<std::vector<float>, 3> tx, tq;
  curve.tables(tx, tq);
  const int P = int(b.size()), H = b.rows(), W = b.cols();
  cv::Mat out(H, W, CV_32FC3);
  parallel_for_rows(H, [&](int r) {
    float* o = out.ptr<float>(r);
    for (int x = 0; x < W; ++x)
      for (int c = 0; c < 3; ++c) {
        float sw = 0, swl = 0;
        for (int j = 0; j < P; ++j) {
          const int z = b.codes[std::size_t(j)].ptr<std::uint16_t>(r)[3 * x + c];
          if (z >= sat) continue;
          const float w = float(std::min(z, b.max_code - z)) + 1e-3f;
          sw += w, swl += w * tx[std::size_t(c)][std::size_t(z)] / float(b.exposures[std::size_t(j)]);
        }
        // Saturated everywhere: the shortest bracket's value (as the merge does).
        o[3 * x + c] = sw > 0 ? swl / sw : tx[std::size_t(c)][b.codes[0].ptr<std::uint16_t>(r)[3 * x + c]] / float(b.exposures[0]);
      }
  });
  return out;
}

}  // namespace rsibr
