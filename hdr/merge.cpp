#include "hdr/merge.h"

#include "core/parallel.h"
#include "hdr/response_recovery.h"

#include <tbb/enumerable_thread_specific.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

// Row kernels are also built for AVX2 and chosen at load time (x86-64 GCC; no FMA, so both builds
// give the same bits).
#if defined(__x86_64__) && defined(__GNUC__)
#define RSIBR_AVX2_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define RSIBR_AVX2_CLONES
#endif

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

// w = mask / (se * Lw + B); sw += w; num += w * L.
RSIBR_AVX2_CLONES void accumulate_row(const float* __restrict mk, const float* __restrict L, const float* __restrict B,
                                      const float* __restrict Lw, float se, float* __restrict sw, float* __restrict num, int W) {
  for (int x = 0; x < W; ++x) {
    const float w = mk[x] / (se * Lw[x] + B[x]);
    sw[x] += w;
    num[x] += w * L[x];
  }
}

// chi2 += mask (L - Lm)^2 / (se * Lm+ + B + eps2 Lm+^2), Lm+ = max(Lm, 0).
RSIBR_AVX2_CLONES void chi2_row(const float* __restrict mk, const float* __restrict L, const float* __restrict B,
                                const float* __restrict Lm, float se, float eps2, float* __restrict chi2, int W) {
  for (int x = 0; x < W; ++x) {
    const float l = std::max(Lm[x], 0.f);
    const float d = L[x] - Lm[x];
    chi2[x] += mk[x] * d * d / (se * l + B[x] + eps2 * l * l);
  }
}

}  // namespace

// Implementation: rows in parallel; within a row, structure of arrays so that the loops over
// pixels vectorise. Per bracket j, channel c and code z the tables hold
//   Lt = X(z) / e_j              (the bracket's radiance estimate)
//   Bt = (read + quant(z)) / e_j^2 (the signal-independent part of var(L_j))
// and var(L_j) = shot * L / e_j + Bt for a radiance L (the pilot, or L_j itself in pass 1).
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
  const std::size_t codes = std::size_t(b.max_code) + 1;
  // Tables indexed [(j * 3 + c) * codes + z].
  std::vector<float> Lt(std::size_t(P) * 3 * codes), Bt(Lt.size());
  float shot_e[kMax][3];
  for (int j = 0; j < P; ++j)
    for (int c = 0; c < 3; ++c) {
      const double e = b.exposures[std::size_t(j)];
      shot_e[j][c] = float(noise.shot[std::size_t(c)] / e);
      for (std::size_t z = 0; z < codes; ++z) {
        Lt[(std::size_t(j) * 3 + std::size_t(c)) * codes + z] = float(tx[std::size_t(c)][z] / e);
        Bt[(std::size_t(j) * 3 + std::size_t(c)) * codes + z] =
            float((noise.read[std::size_t(c)] + tq[std::size_t(c)][z]) / (e * e));
      }
    }
  const float eps2 = float(o.model_error * o.model_error);
  const float ghost_sigmas = float(o.ghost_sigmas);
  const bool pilot = o.pilot_pass;
  const int H = b.rows(), W = b.cols();
  MergedImage m;
  m.radiance.create(H, W, CV_32FC3);
  m.variance.create(H, W, CV_32FC3);
  m.flags.create(H, W, CV_8UC1);
  std::vector<long> counts(std::size_t(H) * 3, 0);
  // Per-thread scratch rows.
  struct Scratch {
    std::vector<float> mask, L, B, sw, swl, num, chi2, n;
  };
  tbb::enumerable_thread_specific<Scratch> scratch([&] {
    Scratch s;
    s.mask.resize(std::size_t(P) * W);
    s.L.resize(std::size_t(P) * W);
    s.B.resize(std::size_t(P) * W);
    s.sw.resize(std::size_t(W));
    s.swl.resize(std::size_t(W));
    s.num.resize(std::size_t(W));
    s.chi2.resize(std::size_t(W));
    s.n.resize(std::size_t(W));
    return s;
  });
  parallel_for_rows(H, [&](int r) {
    Scratch& s = scratch.local();
    const std::uint16_t* row[kMax];
    for (int j = 0; j < P; ++j) row[j] = b.codes[std::size_t(j)].ptr<std::uint16_t>(r);
    float* out = m.radiance.ptr<float>(r);
    float* var = m.variance.ptr<float>(r);
    unsigned char* flag = m.flags.ptr<unsigned char>(r);
    // Usable brackets: no channel saturated.
    std::fill(s.n.begin(), s.n.end(), 0.f);
    std::fill(s.chi2.begin(), s.chi2.end(), 0.f);
    for (int j = 0; j < P; ++j) {
      float* mk = &s.mask[std::size_t(j) * W];
      const std::uint16_t* z = row[j];
      for (int x = 0; x < W; ++x) {
        const bool ok = z[3 * x] < sat && z[3 * x + 1] < sat && z[3 * x + 2] < sat;
        mk[x] = ok ? 1.f : 0.f;
        s.n[std::size_t(x)] += mk[x];
      }
    }
    for (int c = 0; c < 3; ++c) {
      float* sw = s.sw.data();
      float* swl = s.swl.data();
      std::fill(s.sw.begin(), s.sw.end(), 0.f);
      std::fill(s.swl.begin(), s.swl.end(), 0.f);
      // Gather the bracket estimates and pass 1: weights from the measured signal (L_j itself).
      for (int j = 0; j < P; ++j) {
        float* L = &s.L[std::size_t(j) * W];
        float* B = &s.B[std::size_t(j) * W];
        gather_row(row[j] + c, &Lt[(std::size_t(j) * 3 + std::size_t(c)) * codes],
                   &Bt[(std::size_t(j) * 3 + std::size_t(c)) * codes], L, B, W);
        accumulate_row(&s.mask[std::size_t(j) * W], L, B, L, shot_e[j][c], sw, swl, W);
      }
      if (pilot) {
        // Pass 2: weights from the pilot radiance (swl becomes the pilot; sw and num are rebuilt).
        float* num = s.num.data();
        for (int x = 0; x < W; ++x) {
          swl[x] = sw[x] > 0.f ? std::max(swl[x] / sw[x], 0.f) : 0.f;
          sw[x] = 0.f;
          num[x] = 0.f;
        }
        for (int j = 0; j < P; ++j)
          accumulate_row(&s.mask[std::size_t(j) * W], &s.L[std::size_t(j) * W], &s.B[std::size_t(j) * W], swl,
                         shot_e[j][c], sw, num, W);
        std::copy(num, num + W, swl);
      }
      float* Lm = s.num.data();  // the merged channel, contiguous, for the ghost test
      for (int x = 0; x < W; ++x) {
        Lm[x] = sw[x] > 0.f ? swl[x] / sw[x] : 0.f;
        out[3 * x + c] = Lm[x];
        var[3 * x + c] = sw[x] > 0.f ? 1.f / sw[x] : 0.f;
      }
      // Ghost statistic: chi2 += (L_j - L)^2 / (var(L_j) + (model_error L)^2) over usable brackets.
      for (int j = 0; j < P; ++j)
        chi2_row(&s.mask[std::size_t(j) * W], &s.L[std::size_t(j) * W], &s.B[std::size_t(j) * W], Lm, shot_e[j][c],
                 eps2, s.chi2.data(), W);
    }
    for (int x = 0; x < W; ++x) {
      unsigned char f = 0;
      const std::uint16_t* zl = row[P - 1] + 3 * x;
      if (zl[0] == 0 && zl[1] == 0 && zl[2] == 0) f |= kBlack;
      const float n = s.n[std::size_t(x)];
      if (n == 0.f) {
        // Saturated in every bracket: the shortest bracket's value, a lower bound.
        f |= kClipped;
        const std::uint16_t* z = row[0] + 3 * x;
        for (int c = 0; c < 3; ++c) {
          const std::size_t t = std::size_t(c) * codes + z[c];  // bracket 0
          out[3 * x + c] = Lt[t];
          var[3 * x + c] = shot_e[0][c] * Lt[t] + Bt[t];
        }
      } else if (n > 1.f) {
        const float dof = 3.f * (n - 1.f);
        if (s.chi2[std::size_t(x)] > dof + ghost_sigmas * std::sqrt(2.f * dof)) {
          f |= kGhost;
          if (o.deghost) {
            // One bracket instead of a blend of two scenes: the longest usable one (best SNR).
            int j = P - 1;
            while (s.mask[std::size_t(j) * W + std::size_t(x)] == 0.f) --j;
            const std::uint16_t* z = row[j] + 3 * x;
            for (int c = 0; c < 3; ++c) {
              const std::size_t t = (std::size_t(j) * 3 + std::size_t(c)) * codes + z[c];
              out[3 * x + c] = Lt[t];
              var[3 * x + c] = shot_e[j][c] * Lt[t] + Bt[t];
            }
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
  const int sat = saturation_code > 0 ? saturation_code : default_saturation_code(b.max_code);
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
