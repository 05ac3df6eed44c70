#include "hdr/merge.h"

#include "core/avx2_clones.h"
#include "core/parallel.h"
#include "hdr/bracket_statistics.h"
#include "hdr/saturation_level.h"

#include <tbb/enumerable_thread_specific.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace rsibr {
namespace {

// L[x] = lt[z[3x]], B[x] = bt[z[3x]] (one channel of an interleaved RGB row of codes).
RSIBR_AVX2_CLONES void gather_row(const std::uint16_t* __restrict z, const float* __restrict lt,
                                  const float* __restrict bt, float* __restrict L, float* __restrict B, int W) {
  for (int x = 0; x < W; ++x) {
    const int code = z[3 * x];
    L[x] = lt[code];
    B[x] = bt[code];
  }
}

// V = a P+ + B (P+ = max(P, 0)): a bracket's variance for the radiance P.
RSIBR_AVX2_CLONES void variance_row(const float* __restrict P, float a, const float* __restrict B, float* __restrict V,
                                    int W) {
  for (int x = 0; x < W; ++x) V[x] = a * std::max(P[x], 0.f) + B[x];
}

// w = mask / V; sw += w; num += w * L.
RSIBR_AVX2_CLONES void accumulate_row(const float* __restrict mk, const float* __restrict L, const float* __restrict V,
                                      float* __restrict sw, float* __restrict num, int W) {
  for (int x = 0; x < W; ++x) {
    const float w = mk[x] / V[x];
    sw[x] += w;
    num[x] += w * L[x];
  }
}

// s += mask sqrt(T) / V (the weights w = 1 / V times the texture standard deviation).
RSIBR_AVX2_CLONES void texture_sigma_row(const float* __restrict mk, const float* __restrict V,
                                         const float* __restrict T, float* __restrict s, int W) {
  for (int x = 0; x < W; ++x) s[x] += mk[x] * std::sqrt(T[x]) / V[x];
}

// chi2 += mask (L - Lm)^2 / (V + eps2 Lm+^2), Lm+ = max(Lm, 0).
RSIBR_AVX2_CLONES void chi2_row(const float* __restrict mk, const float* __restrict L, const float* __restrict V,
                                const float* __restrict Lm, float eps2, float* __restrict chi2, int W) {
  for (int x = 0; x < W; ++x) {
    const float l = std::max(Lm[x], 0.f);
    const float d = L[x] - Lm[x];
    chi2[x] += mk[x] * d * d / (V[x] + eps2 * l * l);
  }
}

}  // namespace

// Implementation: rows in parallel; within a row, structure of arrays so that the loops over
// pixels vectorise. Per bracket j, channel c and code z the tables hold
//   Lt = X(z) / e_j                                (the bracket's radiance estimate)
//   Bt = (read + (1/12 + code) step(z)^2) / e_j^2   (the signal-independent part of var(L_j))
//   Tt = texture step(z)^2 / e_j^2                  (times a^2: the compression error at busy pixels)
// and var(L_j) = shot L / e_j + Bt for a radiance L (the pilot, or L_j itself in pass 1). The weights
// leave the texture part out (it is about the same in every bracket: a step ~ the gradient of X);
// the output variance adds it as an error common to the brackets,
//   var(L) = 1 / sum w + (sum w sqrt(T))^2 / (sum w)^2,
// and the ghost test allows for it in each bracket's difference from the merge.
MergedImage merge_brackets(const BracketSet& b, const ResponseCurve& curve, const NoiseModel& noise,
                           const MergeOptions& o) {
  if (curve.max_code != b.max_code)
    throw std::invalid_argument("the response curve is for " + std::to_string(curve.max_code) +
                                "-code input, the brackets have codes up to " + std::to_string(b.max_code));
  constexpr int kMax = 32;
  const int P = int(b.size());
  if (P < 1 || P > kMax) throw std::invalid_argument("between 1 and 32 brackets per view");
  int sat[3];
  for (int c = 0; c < 3; ++c) sat[c] = o.saturation_code > 0 ? o.saturation_code : curve.saturation_code(c);
  // Near the top: codes from here up may carry saturated signal pushed down (JPEG).
  int near_top[3];
  for (int c = 0; c < 3; ++c) near_top[c] = sat[c] - b.max_code / 8;
  std::array<std::vector<float>, 3> tx, tq;
  curve.tables(tx, tq);
  const std::size_t codes = std::size_t(b.max_code) + 1;
  // Tables indexed [(j * 3 + c) * codes + z].
  std::vector<float> Lt(std::size_t(P) * 3 * codes), Bt(Lt.size()), Tt(Lt.size());  // Tt: texture a^-2 part of Bt
  float shot_e[kMax][3];
  for (int j = 0; j < P; ++j)
    for (int c = 0; c < 3; ++c) {
      const double e = b.exposures[std::size_t(j)];
      shot_e[j][c] = float(noise.shot[std::size_t(c)] / e);
      for (std::size_t z = 0; z < codes; ++z) {
        Lt[(std::size_t(j) * 3 + std::size_t(c)) * codes + z] = float(tx[std::size_t(c)][z] / e);
        Bt[(std::size_t(j) * 3 + std::size_t(c)) * codes + z] = float(
            (noise.read[std::size_t(c)] + tq[std::size_t(c)][z] * (1 + 12 * noise.code[std::size_t(c)])) / (e * e));
        Tt[(std::size_t(j) * 3 + std::size_t(c)) * codes + z] =
            float(12 * tq[std::size_t(c)][z] * noise.texture[std::size_t(c)] / (e * e));
      }
    }
  // One bracket's variance for the radiance p of channel c (scalar paths).
  auto bracket_var = [&](int j, int c, float p, float Bv) { return shot_e[j][c] * std::max(p, 0.f) + Bv; };
  const bool texture = noise.texture[0] > 0 || noise.texture[1] > 0 || noise.texture[2] > 0;
  const float eps2 = float(o.model_error * o.model_error);
  const float ghost_sigmas = float(o.ghost_sigmas > 0 ? o.ghost_sigmas : b.lossy ? 8.0 : 6.0);
  const bool pilot = o.pilot_pass;
  const int H = b.rows(), W = b.cols();
  MergedImage m;
  m.radiance.create(H, W, CV_32FC3);
  m.variance.create(H, W, CV_32FC3);
  m.flags.create(H, W, CV_8UC1);
  std::vector<long> counts(std::size_t(H) * 3, 0);
  // Per-thread scratch rows.
  struct Scratch {
    std::vector<float> mask, L, B, T, V, sw, sw2v, num, pilot, chi2, n;
    std::vector<unsigned char> chain;
  };
  tbb::enumerable_thread_specific<Scratch> scratch([&] {
    Scratch s;
    s.mask.resize(std::size_t(P) * W);
    s.L.resize(std::size_t(P) * 3 * W);
    s.B.resize(std::size_t(P) * 3 * W);
    s.T.assign(std::size_t(P) * 3 * W, 0.f);
    s.sw2v.resize(std::size_t(3) * W);
    s.V.resize(std::size_t(W));
    s.sw.resize(std::size_t(3) * W);
    s.num.resize(std::size_t(3) * W);
    s.pilot.resize(std::size_t(3) * W);
    s.chi2.resize(std::size_t(W));
    s.n.resize(std::size_t(W));
    s.chain.resize(std::size_t(W));
    return s;
  });
  parallel_for_rows(H, [&](int r) {
    Scratch& s = scratch.local();
    const std::uint16_t* row[kMax];
    for (int j = 0; j < P; ++j) row[j] = b.codes[std::size_t(j)].ptr<std::uint16_t>(r);
    const unsigned char* file_sat[kMax] = {};  // the file's own saturation (RAW), when it has one
    for (int j = 0; j < P && j < int(b.saturated.size()); ++j)
      if (!b.saturated[std::size_t(j)].empty()) file_sat[j] = b.saturated[std::size_t(j)].ptr<unsigned char>(r);
    const unsigned char* cover[kMax] =
        {};  // where the bracket holds data (a shifted or padded file), when not everywhere
    for (int j = 0; j < P && j < int(b.covered.size()); ++j)
      if (!b.covered[std::size_t(j)].empty()) cover[j] = b.covered[std::size_t(j)].ptr<unsigned char>(r);
    auto covers = [&](int j, int x) { return !cover[j] || cover[j][x] != 0; };
    float* out = m.radiance.ptr<float>(r);
    float* var = m.variance.ptr<float>(r);
    unsigned char* flag = m.flags.ptr<unsigned char>(r);
    // Usable brackets: covered, and no channel saturated, here or in a shorter bracket that covers
    // the pixel (s.chain: not saturated so far).
    std::fill(s.n.begin(), s.n.end(), 0.f);
    std::fill(s.chi2.begin(), s.chi2.end(), 0.f);
    std::fill(s.chain.begin(), s.chain.end(), 1);
    for (int j = 0; j < P; ++j) {
      float* mk = &s.mask[std::size_t(j) * W];
      const std::uint16_t* z = row[j];
      for (int x = 0; x < W; ++x) {
        const bool here = covers(j, x);
        if (here &&
            (z[3 * x] >= sat[0] || z[3 * x + 1] >= sat[1] || z[3 * x + 2] >= sat[2] || (file_sat[j] && file_sat[j][x])))
          s.chain[std::size_t(x)] = 0;
        mk[x] = here && s.chain[std::size_t(x)] ? 1.f : 0.f;
      }
    }
    // The bracket estimates and the signal-independent part of their variances, every channel.
    auto Lrow = [&](int j, int c) { return &s.L[(std::size_t(j) * 3 + std::size_t(c)) * W]; };
    auto Brow = [&](int j, int c) { return &s.B[(std::size_t(j) * 3 + std::size_t(c)) * W]; };
    auto Trow = [&](int j, int c) { return &s.T[(std::size_t(j) * 3 + std::size_t(c)) * W]; };
    for (int j = 0; j < P; ++j)
      for (int c = 0; c < 3; ++c) {
        gather_row(row[j] + c, &Lt[(std::size_t(j) * 3 + std::size_t(c)) * codes],
                   &Bt[(std::size_t(j) * 3 + std::size_t(c)) * codes], Lrow(j, c), Brow(j, c), W);
        if (texture) {
          const float* tt = &Tt[(std::size_t(j) * 3 + std::size_t(c)) * codes];
          float* T = Trow(j, c);
          const cv::Mat& img = b.codes[std::size_t(j)];
          for (int x = 0; x < W; ++x) {
            const float a = code_activity(img, r, x, c);
            T[x] = tt[row[j][3 * x + c]] * a * a;
          }
        }
      }
    // Saturated signal below the saturation code: the longest usable bracket, while it is near the
    // top in some channel and reads more than 4 sigma below the shorter usable ones there.
    for (int x = 0; x < W; ++x) {
      for (int j = P - 1; j > 0; --j) {
        if (s.mask[std::size_t(j) * W + std::size_t(x)] == 0.f) continue;
        const std::uint16_t* z = row[j] + 3 * x;
        bool near = false;
        for (int c = 0; c < 3; ++c) near = near || z[c] >= near_top[c];
        if (!near) break;
        bool leaked = false;
        for (int c = 0; c < 3 && !leaked; ++c) {
          if (z[c] < near_top[c]) continue;
          double sw = 0, swl = 0;
          for (int k = 0; k < j; ++k) {
            if (s.mask[std::size_t(k) * W + std::size_t(x)] == 0.f) continue;
            const float l = Lrow(k, c)[x];
            const double w = 1.0 / double(bracket_var(k, c, l, Brow(k, c)[x]));
            sw += w, swl += w * l;
          }
          if (!(sw > 0)) continue;
          const float rest = float(swl / sw);
          const double v = 1.0 / sw + double(bracket_var(j, c, rest, Brow(j, c)[x]));
          leaked = rest - Lrow(j, c)[x] > 4.0 * std::sqrt(v);
        }
        if (!leaked) break;
        s.mask[std::size_t(j) * W + std::size_t(x)] = 0.f;
      }
    }
    for (int j = 0; j < P; ++j)
      for (int x = 0; x < W; ++x) s.n[std::size_t(x)] += s.mask[std::size_t(j) * W + std::size_t(x)];
    float* V = s.V.data();
    auto sw = [&](int c) { return &s.sw[std::size_t(c) * W]; };
    auto num = [&](int c) { return &s.num[std::size_t(c) * W]; };
    auto pil = [&](int c) { return &s.pilot[std::size_t(c) * W]; };
    auto sw2v = [&](int c) { return &s.sw2v[std::size_t(c) * W]; };
    // Pass 1: weights from the measured signal (each bracket's own estimates).
    std::fill(s.sw.begin(), s.sw.end(), 0.f);
    std::fill(s.num.begin(), s.num.end(), 0.f);
    for (int j = 0; j < P; ++j)
      for (int c = 0; c < 3; ++c) {
        variance_row(Lrow(j, c), shot_e[j][c], Brow(j, c), V, W);
        accumulate_row(&s.mask[std::size_t(j) * W], Lrow(j, c), V, sw(c), num(c), W);
      }
    if (pilot) {
      // Pass 2: weights from the pilot radiance.
      for (int c = 0; c < 3; ++c)
        for (int x = 0; x < W; ++x) pil(c)[x] = sw(c)[x] > 0.f ? std::max(num(c)[x] / sw(c)[x], 0.f) : 0.f;
      std::fill(s.sw.begin(), s.sw.end(), 0.f);
      std::fill(s.num.begin(), s.num.end(), 0.f);
      std::fill(s.sw2v.begin(), s.sw2v.end(), 0.f);
      for (int j = 0; j < P; ++j)
        for (int c = 0; c < 3; ++c) {
          variance_row(pil(c), shot_e[j][c], Brow(j, c), V, W);
          accumulate_row(&s.mask[std::size_t(j) * W], Lrow(j, c), V, sw(c), num(c), W);
          if (texture) texture_sigma_row(&s.mask[std::size_t(j) * W], V, Trow(j, c), sw2v(c), W);
        }
    }
    // The merge (into pilot's rows, contiguous per channel, for the ghost test).
    for (int c = 0; c < 3; ++c)
      for (int x = 0; x < W; ++x) {
        const float swx = sw(c)[x];
        const float Lm = swx > 0.f ? num(c)[x] / swx : 0.f;
        pil(c)[x] = Lm;
        out[3 * x + c] = Lm;
        var[3 * x + c] = swx > 0.f ? 1.f / swx + (texture && pilot ? sw2v(c)[x] * sw2v(c)[x] / (swx * swx) : 0.f) : 0.f;
      }
    // Ghost statistic: chi2 += (L_j - L)^2 / (var(L_j) + (model_error L)^2) over usable brackets.
    for (int j = 0; j < P; ++j)
      for (int c = 0; c < 3; ++c) {
        variance_row(pil(c), shot_e[j][c], Brow(j, c), V, W);
        if (texture)
          for (int x = 0; x < W; ++x) V[x] += Trow(j, c)[x];
        chi2_row(&s.mask[std::size_t(j) * W], Lrow(j, c), V, pil(c), eps2, s.chi2.data(), W);
      }
    for (int x = 0; x < W; ++x) {
      unsigned char f = 0;
      int longest = P - 1, shortest = 0;  // that cover the pixel (the middle bracket always does)
      while (longest > 0 && !covers(longest, x)) --longest;
      while (shortest < P - 1 && !covers(shortest, x)) ++shortest;
      const std::uint16_t* zl = row[longest] + 3 * x;
      if (zl[0] == 0 && zl[1] == 0 && zl[2] == 0) f |= kBlack;
      const float n = s.n[std::size_t(x)];
      // One bracket's value and variance (clipped: the shortest; deghosted: the longest usable).
      auto single = [&](int j) {
        for (int c = 0; c < 3; ++c) {
          const float l = Lrow(j, c)[x];
          out[3 * x + c] = l;
          var[3 * x + c] = bracket_var(j, c, l, Brow(j, c)[x] + Trow(j, c)[x]);
        }
      };
      if (n == 0.f) {
        // Saturated in every bracket: the shortest bracket's value, a lower bound.
        f |= kClipped;
        single(shortest);
      } else if (n > 1.f) {
        // The channels' residuals are correlated (a JPEG's luma error and a colour matrix's shot noise
        // reach all three), so the test takes them as one measurement: mean chi2 over channels
        // against n - 1 degrees of freedom (under independence it is only tighter than that).
        const float dof = n - 1.f;
        if (s.chi2[std::size_t(x)] / 3.f > dof + ghost_sigmas * std::sqrt(2.f * dof)) {
          f |= kGhost;
          if (o.deghost) {
            // One bracket instead of a blend of two scenes: the longest usable one (best SNR).
            int j = P - 1;
            while (s.mask[std::size_t(j) * W + std::size_t(x)] == 0.f) --j;
            single(j);
          }
        }
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
  // Debevec & Malik 1997, eq. 6: ln L = sum_j w(z_j) (ln X(z_j) - ln e_j) / sum_j w(z_j) with the hat
  // w(z) = min(z, max_code - z) (zero at both ends), per channel, saturated codes left out.
  int satc[3];
  for (int c = 0; c < 3; ++c) satc[c] = saturation_code > 0 ? saturation_code : curve.saturation_code(c);
  std::array<std::vector<float>, 3> tx, tq;
  curve.tables(tx, tq);
  const int P = int(b.size()), H = b.rows(), W = b.cols();
  std::vector<float> log_e(std::size_t(P), 0.f);
  for (int j = 0; j < P; ++j) log_e[std::size_t(j)] = float(std::log(b.exposures[std::size_t(j)]));
  cv::Mat out(H, W, CV_32FC3);
  parallel_for_rows(H, [&](int r) {
    float* o = out.ptr<float>(r);
    for (int x = 0; x < W; ++x)
      for (int c = 0; c < 3; ++c) {
        const int sat = satc[c];
        float sw = 0, swl = 0;
        for (int j = 0; j < P; ++j) {
          const int z = b.codes[std::size_t(j)].ptr<std::uint16_t>(r)[3 * x + c];
          const float X = tx[std::size_t(c)][std::size_t(z)];
          if (z >= sat || !(X > 0)) continue;
          const float w = float(std::min(z, b.max_code - z));
          sw += w, swl += w * (std::log(X) - log_e[std::size_t(j)]);
        }
        // No weight anywhere: saturated (the shortest bracket's value, as the merge) or black (0).
        const int z0 = b.codes[0].ptr<std::uint16_t>(r)[3 * x + c];
        o[3 * x + c] = sw > 0 ? std::exp(swl / sw)
                              : (z0 >= sat ? tx[std::size_t(c)][std::size_t(z0)] / float(b.exposures[0]) : 0.f);
      }
  });
  return out;
}

}  // namespace rsibr
