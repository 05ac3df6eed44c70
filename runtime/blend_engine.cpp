#include "runtime/blend_engine.h"

#include "core/albedo_normalisation.h"
#include "core/avx2_clones.h"
#include "core/resolution_mask.h"
#include "core/sphere_map.h"
#include "runtime/disc_sampler.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <mutex>
#include <stdexcept>
#include <string>

namespace rsibr {

// One view in the kernel's layout. texels: (height + 2) rows of (width + 2) RGBA texels, the map
// with a one-texel border; a texel whose centre lies inside the disc (sample_disc's test, the same
// double arithmetic) holds (R, G, B, 1), every other texel and the border (0, 0, 0, 0). A bilinear
// footprint's sum then carries the valid taps' weight in its fourth lane, which is sample_disc's
// renormalisation, and every disc point |xy| <= 1 has its four taps inside the padded image.
// confidence: the same grid, the confidence where the tap is valid, else 0 (empty: no channel used).
struct BlendEngine::Source {
  DiscMap original;  // sample_disc's inward steps where no tap is valid (beyond the disc's edge)
  CentralDirection kind = CentralDirection::Mirror;
  Mat3 view_from_world = Mat3::Identity();
  std::vector<float> texels, confidence;
  struct Grid {
    int stride = 0;  // floats per padded row of texels (4 (width + 2))
    // Padded pixel position of disc point (x, y): (x scale_x + offset_x, offset_y - y scale_y),
    // clamped to [0, max_x] x [0, max_y] so that the footprint stays in the padded image.
    float scale_x = 0, offset_x = 0, scale_y = 0, offset_y = 0, max_x = 0, max_y = 0;
    // Squared disc radius inside which a point's four taps are all valid (-1: nowhere).
    float interior2 = -1;
  } grid;
  int conf_stride = 0;  // floats per padded row of confidence (width + 2)
  int width = 0, height = 0;
  // Coarser levels for lookups at a footprint (blend_engine.h): coarser[l - 1] is level l, max(1,
  // W >> l) x max(1, H >> l) texels in the same padded layout, each the mean of the finer texels it
  // covers (RGBA and confidence), down to 1 x 1. Built on first use (source_pyramid).
  struct Level {
    std::vector<float> texels, confidence;
    Grid grid;
    int conf_stride = 0, width = 0, height = 0;
  };
  std::vector<Level> coarser;
  std::unique_ptr<MaskPyramid> mask;  // mixed-resolution sets: the authored mask (blend_engine.h)
};

struct BlendEngine::Cache {
  std::vector<std::unique_ptr<Source>> sources;
  std::unique_ptr<std::once_flag[]> once, pyramid_once;
};

namespace {

using Source = BlendEngine::Source;

Source make_source(const MapView& v, bool use_confidence) {
  Source s;
  const int W = v.rgb.cols, H = v.rgb.rows;
  s.original = DiscMap{&v.rgb, use_confidence && !v.confidence.empty() ? &v.confidence : nullptr, W, H};
  s.kind = v.warp;
  s.view_from_world = v.world_from_view.transpose();
  const std::size_t PW = std::size_t(W) + 2, PH = std::size_t(H) + 2;
  if (4 * PW * PH > std::size_t(std::numeric_limits<int>::max()))  // tap offsets are int
    throw std::invalid_argument("blend: a " + std::to_string(W) + "x" + std::to_string(H) + " map is too large");
  s.grid.stride = int(4 * PW);
  s.conf_stride = int(PW);
  s.texels.assign(4 * PW * PH, 0.0f);
  if (s.original.confidence) s.confidence.assign(PW * PH, 0.0f);
  // Rows in parallel; per row the texels inside the disc are disc_span's columns (the same test).
  const cv::Mat* conf = s.original.confidence;
  float* texels = s.texels.data();
  float* confidence = s.confidence.empty() ? nullptr : s.confidence.data();
  tbb::parallel_for(tbb::blocked_range<int>(0, H, 16), [&](const tbb::blocked_range<int>& rows) {
    for (int r = rows.begin(); r != rows.end(); ++r) {
      const auto [c0, c1] = disc_span(r, W, H);
      const float* in = v.rgb.ptr<float>(r);
      float* out = texels + (std::size_t(r) + 1) * 4 * PW + 4;
      for (int c = c0; c < c1; ++c) {
        out[4 * c] = in[3 * c];
        out[4 * c + 1] = in[3 * c + 1];
        out[4 * c + 2] = in[3 * c + 2];
        out[4 * c + 3] = 1.0f;
      }
      if (confidence) {
        const float* cin = conf->ptr<float>(r);
        std::copy(cin + c0, cin + c1, confidence + (std::size_t(r) + 1) * PW + 1 + c0);
      }
    }
  });
  s.grid.scale_x = float(0.5 * W);
  s.grid.offset_x = float(0.5 * (W + 1));  // pixel_from_disc's (W - 1)/2, plus the border
  s.grid.scale_y = float(0.5 * H);
  s.grid.offset_y = float(0.5 * (H + 1));
  s.grid.max_x = float(W) + 0.5f;  // floor <= W: the right tap at W + 1, the padded image's last column
  s.grid.max_y = float(H) + 0.5f;
  // A footprint's taps lie within one texel of the point in x and in y: within a disc-unit distance
  // sqrt((2/W)^2 + (2/H)^2); points inside radius 1 - that (less a margin for float rounding) have
  // all four inside the disc.
  const double radius = 1.0 - std::sqrt(4.0 / (double(W) * W) + 4.0 / (double(H) * H)) - 1e-4;
  s.grid.interior2 = radius > 0 ? float(radius * radius) : -1.0f;
  s.width = W;
  s.height = H;
  return s;
}

// The grid of a w x h level in the kernel's padded layout (make_source's formulas); its footprints
// always take the renormalising path (interior2 = -1).
Source::Grid level_grid(int w, int h) {
  Source::Grid g;
  g.stride = 4 * (w + 2);
  g.scale_x = float(0.5 * w);
  g.offset_x = float(0.5 * (w + 1));
  g.scale_y = float(0.5 * h);
  g.offset_y = float(0.5 * (h + 1));
  g.max_x = float(w) + 0.5f;
  g.max_y = float(h) + 0.5f;
  g.interior2 = -1.0f;
  return g;
}

// The texels [begin, end) of a finer level that texel i of the next coarser level covers: two, and
// the remainder for the last texel of an odd size.
std::pair<int, int> children(int i, int coarse_size, int fine_size) {
  const int begin = std::min(2 * i, fine_size - 1);
  return {begin, i == coarse_size - 1 ? fine_size : std::min(2 * i + 2, fine_size)};
}

// Source s's coarser levels: each texel the mean of the finer level's texels it covers.
void build_levels(Source& s) {
  int w = s.width, h = s.height;
  while (w > 1 || h > 1) {
    const bool first = s.coarser.empty();
    const float* fine = first ? s.texels.data() : s.coarser.back().texels.data();
    const float* fine_conf = first
                                 ? (s.confidence.empty() ? nullptr : s.confidence.data())
                                 : (s.coarser.back().confidence.empty() ? nullptr : s.coarser.back().confidence.data());
    const int fine_pw = w + 2;
    Source::Level L;
    L.width = std::max(1, w >> 1);
    L.height = std::max(1, h >> 1);
    const int pw = L.width + 2, ph = L.height + 2;
    L.texels.assign(std::size_t(4) * pw * ph, 0.0f);
    if (fine_conf) L.confidence.assign(std::size_t(pw) * ph, 0.0f);
    for (int r = 0; r < L.height; ++r) {
      const auto [r0, r1] = children(r, L.height, h);
      for (int c = 0; c < L.width; ++c) {
        const auto [c0, c1] = children(c, L.width, w);
        float sum[4] = {0, 0, 0, 0}, conf = 0;
        for (int fr = r0; fr < r1; ++fr)
          for (int fc = c0; fc < c1; ++fc) {
            const std::size_t at = std::size_t(fr + 1) * fine_pw + std::size_t(fc + 1);
            for (int k = 0; k < 4; ++k) sum[k] += fine[4 * at + k];
            if (fine_conf) conf += fine_conf[at];
          }
        const float inv = 1.0f / float((r1 - r0) * (c1 - c0));
        const std::size_t at = std::size_t(r + 1) * pw + std::size_t(c + 1);
        for (int k = 0; k < 4; ++k) L.texels[4 * at + k] = sum[k] * inv;
        if (fine_conf) L.confidence[at] = conf * inv;
      }
    }
    L.grid = level_grid(L.width, L.height);
    L.conf_stride = pw;
    w = L.width;
    h = L.height;
    s.coarser.push_back(std::move(L));
  }
}

// The source's resolution mask (core/resolution_mask.h) from its coverage: the confidence where a
// texel is valid (1 without a channel), 0 outside the disc.
std::unique_ptr<MaskPyramid> make_mask(const Source& s, double detail_level) {
  const int W = s.width, H = s.height, pw = W + 2;
  cv::Mat coverage(H, W, CV_32FC1);
  for (int r = 0; r < H; ++r)
    for (int c = 0; c < W; ++c) {
      const std::size_t at = std::size_t(r + 1) * pw + std::size_t(c + 1);
      coverage.at<float>(r, c) = s.texels[4 * at + 3] > 0.0f ? (s.confidence.empty() ? 1.0f : s.confidence[at]) : 0.0f;
    }
  return resolution_mask(coverage, detail_level);
}

// Four floats (GCC/Clang vector extension): one texel's RGBA, or R, G, B and the weight sum.
typedef float v4f __attribute__((vector_size(16)));
inline v4f load4(const float* p) {
  v4f v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
// Eight floats: two horizontally adjacent texels (passed by reference: no vector ABI question for
// the builds without AVX).
typedef float v8f __attribute__((vector_size(32)));
inline void load8(const float* p, v8f& v) { std::memcpy(&v, p, sizeof v); }
inline v4f halves_sum(const v8f& v) {
  v4f lo, hi;
  std::memcpy(&lo, &v, sizeof lo);
  std::memcpy(&hi, reinterpret_cast<const char*>(&v) + sizeof lo, sizeof hi);
  return lo + hi;
}

// --- The kernel: fade, footprint, tap and sum of one (texel, source), and the texel's result. ---

// a = weight * fade(rim): rim_fade_weight's formula in float.
inline float faded(float weight, float rim, float inv_fade) {
  if (!(inv_fade > 0.0f)) return weight;
  const float t = std::min(rim * inv_fade, 1.0f);
  return rim > 0.0f ? weight * (t * t * (3.0f - 2.0f * t)) : 0.0f;
}

// The bilinear footprint of disc point (x, y): the offset of its top-left tap in floats and the
// fractions. NaN goes to the corner (0, 0).
inline void footprint(const Source::Grid& s, float x, float y, int& offset, float& fx, float& fy) {
  float px = x * s.scale_x + s.offset_x, py = s.offset_y - y * s.scale_y;
  px = px > 0.0f ? px : 0.0f;
  py = py > 0.0f ? py : 0.0f;
  px = px < s.max_x ? px : s.max_x;
  py = py < s.max_y ? py : s.max_y;
  const int c0 = int(px), r0 = int(py);  // >= 0: truncation is floor
  fx = px - float(c0);
  fy = py - float(r0);
  offset = r0 * s.stride + 4 * c0;
}

// Adds source s's contribution at weight a (> 0) to acc (R, G, B, total); returns the contribution
// a c (0: none). (x, y) are only read where no tap is valid (sample_disc's inward steps).
inline float accumulate(const Source& s, float a, int offset, float fx, float fy, float x, float y, v4f& acc) {
  const float w00 = (1.0f - fx) * (1.0f - fy), w01 = fx * (1.0f - fy), w10 = (1.0f - fx) * fy, w11 = fx * fy;
  const float* t0 = s.texels.data() + offset;
  const float* t1 = t0 + s.grid.stride;
  v4f S = w00 * load4(t0) + w01 * load4(t0 + 4) + w10 * load4(t1) + w11 * load4(t1 + 4);
  float valid = S[3];
  float conf = 1.0f;
  if (valid > 0.0f) {
    if (!s.confidence.empty()) {
      const float* k0 = s.confidence.data() + offset / 4;
      const float* k1 = k0 + s.conf_stride;
      // The same products in the same order as S[3]: exactly 1 for a confidence of 1.
      const float c = (w00 * k0[0] + w01 * k0[1] + w10 * k1[0] + w11 * k1[1]) / valid;
      conf = c > 0.0f ? c : 0.0f;  // negative or NaN counts as 0
    }
  } else {
    double L[3], cd;
    if (!sample_disc(s.original, Vec2(x, y), L, &cd)) return 0.0f;
    S = v4f{float(L[0]), float(L[1]), float(L[2]), 1.0f};
    valid = 1.0f;
    conf = float(cd);
  }
  a *= conf;
  if (!(a > 0.0f)) return 0.0f;
  acc += (a / valid) * S;  // fourth lane: a
  return a;
}

// out = acc / total (RGB), weight = total (at most 1: the float sum of barycentric weights may
// round above it); false where total is 0 (the fallback decides).
inline bool finish(const v4f& acc, float* out, float* weight) {
  const float total = acc[3];
  if (!(total > 0.0f)) return false;
  const float inv = 1.0f / total;
  out[0] = acc[0] * inv;
  out[1] = acc[1] * inv;
  out[2] = acc[2] * inv;
  *weight = total < 1.0f ? total : 1.0f;
  return true;
}

// The fallback (step 5): the least-faded located source (largest rim, ties to the first) at its disc
// point, through sample_disc. warp_of(k) gives located source k's WarpSample. Writes 0 when even that
// has no valid tap.
template <class WarpOf>
void fallback(const Source* const* sources, int n, const WarpOf& warp_of, float* out) {
  int best = -1;
  WarpSample best_sample;
  for (int k = 0; k < n; ++k) {
    const WarpSample ws = warp_of(k);
    if (best < 0 || ws.rim > best_sample.rim) {
      best = k;
      best_sample = ws;
    }
  }
  double L[3], conf;
  const bool ok = best >= 0 && sample_disc(sources[best]->original, best_sample.disc, L, &conf);
  for (int j = 0; j < 3; ++j) out[j] = ok ? float(L[j]) : 0.0f;
}

// --- Row forms of the kernel (vectorised, also for AVX2 and AVX-512). ---

// The footprint of disc point (x, y) for a source weight a: the offset of its top-left tap (>= 0
// when all four taps are valid, inside the grid's interior radius; kRim otherwise; kSkip where a
// is not > 0) and the four tap weights times a, w = (w00, w01, w10, w11) = ((1 - fx)(1 - fy),
// fx (1 - fy), (1 - fx) fy, fx fy) a: top-left, top-right, bottom-left, bottom-right.
constexpr int kSkip = -1, kRim = -2;
struct Taps {
  int offset;
  float w[4];
};
inline Taps taps(const Source::Grid& g, float x, float y, float a) {
  Taps t;
  float fx, fy;
  footprint(g, x, y, t.offset, fx, fy);
  const float ya = (1.0f - fy) * a, yb = fy * a, gx = 1.0f - fx;
  t.w[0] = gx * ya;
  t.w[1] = fx * ya;
  t.w[2] = gx * yb;
  t.w[3] = fx * yb;
  const bool interior = x * x + y * y <= g.interior2;
  t.offset = a > 0.0f ? (interior ? t.offset : kRim) : kSkip;
  return t;
}

// Out of line: the rare path stays out of the hot loops' registers.
__attribute__((noinline)) float contribute_rim(const Source& s, float a, float x, float y, v4f& acc) {
  int o;
  float fx, fy;
  footprint(s.grid, x, y, o, fx, fy);
  return accumulate(s, a, o, fx, fy, x, y, acc);
}

// The weighted sum of an interior footprint's four RGBA taps, in one order for every path (so the
// single texel here and the pairs in gather_row give the same bits): per lane
// (w00 t00 + w10 t10) + (w01 t01 + w11 t11).
inline v4f interior_sum(const float* t0, int stride, const float* w) {
  const v8f W0 = {w[0], w[0], w[0], w[0], w[1], w[1], w[1], w[1]};
  const v8f W1 = {w[2], w[2], w[2], w[2], w[3], w[3], w[3], w[3]};
  v8f T0, T1;
  load8(t0, T0);
  load8(t0 + stride, T1);
  return halves_sum(W0 * T0 + W1 * T1);
}

// The confidence of an interior footprint, c = sum w k / sum w (exactly 1 for a confidence of 1: the
// same products in the same order above and below the division); negative or NaN counts as 0.
inline float tap_confidence(const float* confidence, int conf_stride, int offset, const float* w) {
  const float* k0 = confidence + offset / 4;
  const float* k1 = k0 + conf_stride;
  const float c = (w[0] * k0[0] + w[1] * k0[1] + w[2] * k1[0] + w[3] * k1[1]) / (w[0] + w[1] + w[2] + w[3]);
  return c > 0.0f ? c : 0.0f;
}

// An interior footprint's contribution (every tap valid, offset >= 0): the four taps times the
// premultiplied weights (no renormalisation: the weights sum to a up to rounding), times the
// confidence c (tap_confidence) when kConfidence. Adds it to acc (R, G, B, total) and returns a c
// (0: none).
template <bool kConfidence>
inline float contribute_interior(const float* texels, const float* confidence, int stride, int conf_stride, int offset,
                                 const float* w, float a, v4f& acc) {
  const v4f S = interior_sum(texels + offset, stride, w);
  if (!kConfidence) {
    acc += S;
    return a;
  }
  const float conf = tap_confidence(confidence, conf_stride, offset, w);
  if (!(conf > 0.0f)) return 0.0f;
  acc += conf * S;
  return a * conf;
}

// Adds source s's contribution to acc (R, G, B, total) and returns it (a c; 0: none): interior
// footprints by contribute_interior, rim footprints by accumulate() (renormalised, or sample_disc's
// inward steps).
inline float contribute(const Source& s, const Taps& t, float a, float x, float y, v4f& acc) {
  if (t.offset < 0) return t.offset == kSkip ? 0.0f : contribute_rim(s, a, x, y, acc);
  return s.confidence.empty()
             ? contribute_interior<false>(s.texels.data(), nullptr, s.grid.stride, 0, t.offset, t.w, a, acc)
             : contribute_interior<true>(s.texels.data(), s.confidence.data(), s.grid.stride, s.conf_stride, t.offset,
                                         t.w, a, acc);
}

// The source weights a = weight * fade(rim) and taps() for a row of points, structure of arrays for
// the offsets, the four weights of texel i at w[4i .. 4i + 3] (one loop that vectorises, also for
// AVX2 and AVX-512).
constexpr int kTileCols = 512;  // destination texels per tile row
struct TapRows {
  int offset[kTileCols];
  alignas(64) float w[4 * kTileCols];
};
RSIBR_AVX512_CLONES void taps_row(const Source::Grid& grid, int n, float weight, float inv_fade,
                                  const float* __restrict x, const float* __restrict y, const float* __restrict rim,
                                  float* __restrict a, TapRows& out) {
  const Source::Grid g = grid;  // a local: the stores below could otherwise alias it
  for (int i = 0; i < n; ++i) {
    const float ai = faded(weight, rim[i], inv_fade);
    a[i] = ai;
    const Taps t = taps(g, x[i], y[i], ai);
    out.offset[i] = t.offset;
    out.w[4 * i] = t.w[0];
    out.w[4 * i + 1] = t.w[1];
    out.w[4 * i + 2] = t.w[2];
    out.w[4 * i + 3] = t.w[3];
  }
}

// finish() for a row of n texels: out (RGB), out_w; the texels whose total is not > 0 get weight 0
// and are listed in `missing` for the fallback (their count returned). The same arithmetic as finish.
RSIBR_AVX512_CLONES int finish_row(int n, const v4f* __restrict acc, float* __restrict out, float* __restrict out_w,
                                   int* __restrict missing) {
  float inv[kTileCols];
  int none = 0;  // texels without a sum (rare: the scan below runs only when there are some)
  for (int i = 0; i < n; ++i) {
    const float total = acc[i][3];
    const bool some = total > 0.0f;
    none += some ? 0 : 1;
    inv[i] = 1.0f / (some ? total : 1.0f);
    out_w[i] = some ? (total < 1.0f ? total : 1.0f) : 0.0f;
  }
  for (int i = 0; i < n; ++i) {
    out[3 * i] = acc[i][0] * inv[i];
    out[3 * i + 1] = acc[i][1] * inv[i];
    out[3 * i + 2] = acc[i][2] * inv[i];
  }
  int count = 0;
  if (none > 0)
    for (int i = 0; i < n; ++i)
      if (!(acc[i][3] > 0.0f)) missing[count++] = i;
  return count;
}

// contribute() for a row of texels (acc and source_weight per texel; source_weight may be null), with
// the source's pointers and the two options hoisted out of the loop (four forms). Two neighbouring
// interior texels are summed at once (16 lanes: both texels' top tap pairs, then their bottom pairs),
// with contribute_interior's arithmetic per lane; a pair with a rim or skipped texel, or a texel of
// confidence 0, goes one texel at a time.
typedef float v16f __attribute__((vector_size(64)));
template <bool kConfidence, bool kSourceWeight>
__attribute__((always_inline)) inline void gather_row_t(const Source& s, int n, const float* a, const float* x,
                                                        const float* y, const TapRows& t, v4f* acc,
                                                        float* source_weight) {
  const float* texels = s.texels.data();
  const float* confidence = s.confidence.data();
  const int stride = s.grid.stride, conf_stride = s.conf_stride;
  const auto one = [&](int i) __attribute__((always_inline)) {
    const int offset = t.offset[i];
    if (offset == kSkip) return;
    const float c = offset >= 0 ? contribute_interior<kConfidence>(texels, confidence, stride, conf_stride, offset,
                                                                   t.w + 4 * i, a[i], acc[i])
                                : contribute_rim(s, a[i], x[i], y[i], acc[i]);
    if (kSourceWeight) source_weight[i] = c;
  };
  int i = 0;
  for (; i + 1 < n; i += 2) {
    const int o0 = t.offset[i], o1 = t.offset[i + 1];
    float c0 = 1.0f, c1 = 1.0f;
    if (kConfidence && (o0 | o1) >= 0) {
      c0 = tap_confidence(confidence, conf_stride, o0, t.w + 4 * i);
      c1 = tap_confidence(confidence, conf_stride, o1, t.w + 4 * i + 4);
    }
    if ((o0 | o1) < 0 || !(c0 > 0.0f) || !(c1 > 0.0f)) {
      one(i);
      one(i + 1);
      continue;
    }
    v8f w, A0, A1, B0, B1;
    std::memcpy(&w, t.w + 4 * i, sizeof w);
    load8(texels + o0, A0);
    load8(texels + o0 + stride, A1);
    load8(texels + o1, B0);
    load8(texels + o1 + stride, B1);
    const v16f T0 = __builtin_shufflevector(A0, B0, 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
    const v16f T1 = __builtin_shufflevector(A1, B1, 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
    const v16f W0 = __builtin_shufflevector(w, w, 0, 0, 0, 0, 1, 1, 1, 1, 4, 4, 4, 4, 5, 5, 5, 5);
    const v16f W1 = __builtin_shufflevector(w, w, 2, 2, 2, 2, 3, 3, 3, 3, 6, 6, 6, 6, 7, 7, 7, 7);
    const v16f S = W0 * T0 + W1 * T1;
    // Lanes 0-3 + 4-7: texel i's sum; 8-11 + 12-15: texel i + 1's (halves_sum's order).
    const v8f lo = __builtin_shufflevector(S, S, 0, 1, 2, 3, 8, 9, 10, 11);
    const v8f hi = __builtin_shufflevector(S, S, 4, 5, 6, 7, 12, 13, 14, 15);
    v8f sum = lo + hi, pair;
    if (kConfidence) sum *= v8f{c0, c0, c0, c0, c1, c1, c1, c1};
    std::memcpy(&pair, acc + i, sizeof pair);
    pair += sum;
    std::memcpy(acc + i, &pair, sizeof pair);
    if (kSourceWeight) {
      source_weight[i] = kConfidence ? a[i] * c0 : a[i];
      source_weight[i + 1] = kConfidence ? a[i + 1] * c1 : a[i + 1];
    }
  }
  for (; i < n; ++i) one(i);
}
RSIBR_AVX512_CLONES void gather_row(const Source& s, int n, const float* a, const float* x, const float* y,
                                    const TapRows& t, v4f* acc, float* source_weight) {
  const bool conf = !s.confidence.empty();
  if (source_weight)
    conf ? gather_row_t<true, true>(s, n, a, x, y, t, acc, source_weight)
         : gather_row_t<false, true>(s, n, a, x, y, t, acc, source_weight);
  else
    conf ? gather_row_t<true, false>(s, n, a, x, y, t, acc, nullptr)
         : gather_row_t<false, false>(s, n, a, x, y, t, acc, nullptr);
}

// --- Lookups at a footprint (radiance at a level of detail). ---

// Level `level` of source s at disc point (x, y): the colour (bilinear, renormalised by the taps'
// validity) and the confidence (the same weights); false where no tap holds a valid share.
bool sample_level(const Source& s, int level, float x, float y, float rgb[3], float& conf) {
  const float* texels = level == 0 ? s.texels.data() : s.coarser[std::size_t(level - 1)].texels.data();
  const std::vector<float>& cv = level == 0 ? s.confidence : s.coarser[std::size_t(level - 1)].confidence;
  const Source::Grid& g = level == 0 ? s.grid : s.coarser[std::size_t(level - 1)].grid;
  const int conf_stride = level == 0 ? s.conf_stride : s.coarser[std::size_t(level - 1)].conf_stride;
  int o;
  float fx, fy;
  footprint(g, x, y, o, fx, fy);
  const float w00 = (1.0f - fx) * (1.0f - fy), w01 = fx * (1.0f - fy), w10 = (1.0f - fx) * fy, w11 = fx * fy;
  const float* t0 = texels + o;
  const float* t1 = t0 + g.stride;
  const v4f S = w00 * load4(t0) + w01 * load4(t0 + 4) + w10 * load4(t1) + w11 * load4(t1 + 4);
  if (!(S[3] > 1e-6f)) return false;
  const float inv = 1.0f / S[3];
  rgb[0] = S[0] * inv;
  rgb[1] = S[1] * inv;
  rgb[2] = S[2] * inv;
  conf = 1.0f;
  if (!cv.empty()) {
    const float* k0 = cv.data() + o / 4;
    const float* k1 = k0 + conf_stride;
    const float c = (w00 * k0[0] + w01 * k0[1] + w10 * k1[0] + w11 * k1[1]) * inv;
    conf = c > 0.0f ? c : 0.0f;
  }
  return true;
}

// Source s's contribution at weight a (> 0) and level of detail lod, trilinear between the two
// nearest levels; lod <= 0 is contribute()'s tap exactly, and so is a lookup no level can serve.
float contribute_lod(const Source& s, float a, float x, float y, double lod, v4f& acc) {
  if (!(lod > 0) || s.coarser.empty()) return contribute(s, taps(s.grid, x, y, a), a, x, y, acc);
  const double l = std::min(lod, double(s.coarser.size()));
  const int l0 = int(l);
  const float f = float(l - l0);
  float c0[3], c1[3], k0 = 0, k1 = 0;
  const bool ok0 = sample_level(s, l0, x, y, c0, k0);
  const bool ok1 = f > 0.0f && l0 + 1 <= int(s.coarser.size()) && sample_level(s, l0 + 1, x, y, c1, k1);
  float rgb[3], conf;
  if (ok0 && ok1) {
    for (int k = 0; k < 3; ++k) rgb[k] = (1.0f - f) * c0[k] + f * c1[k];
    conf = (1.0f - f) * k0 + f * k1;
  } else if (ok0 || ok1) {
    for (int k = 0; k < 3; ++k) rgb[k] = ok0 ? c0[k] : c1[k];
    conf = ok0 ? k0 : k1;
  } else {
    return contribute(s, taps(s.grid, x, y, a), a, x, y, acc);
  }
  const float ac = a * conf;
  if (!(ac > 0.0f)) return 0.0f;
  acc += v4f{ac * rgb[0], ac * rgb[1], ac * rgb[2], ac};
  return ac;
}

// The level of detail of a lookup at disc point p whose footprint's corners land at q1 and q2 (disc
// coordinates): log2 of the larger extent in texels of a width-W map, at least 0.
double lod_of(const Vec2& p, const Vec2& q1, const Vec2& q2, int W) {
  const double extent = std::max((q1 - p).norm(), (q2 - p).norm()) * 0.5 * W;
  return extent > 1.0 ? std::log2(extent) : 0.0;
}

double det3(const Vec3& a, const Vec3& b, const Vec3& c) { return a.dot(b.cross(c)); }

// v / |v|, as core/view_set.cpp's locate normalises (so the hinted weights are bitwise its weights).
Vec3 unit(const Vec3& v) {
  const double sq = v.squaredNorm();
  if (sq > 1e-290 && sq < 1e290) return v.normalized();
  return (v / v.cwiseAbs().maxCoeff()).normalized();
}

// n clamped to v's hemisphere: a normal facing away (n . v < 0, a shading normal past the
// silhouette) becomes the nearest rim normal, *nv = max(n . v, 0).
Vec3 normal_facing(const Vec3& n_in, const Vec3& v, double* nv) {
  Vec3 n = n_in;
  *nv = n.dot(v);
  if (!(*nv < 0)) return n;
  n -= *nv * v;
  *nv = 0;
  const double len = n.norm();
  return len > 0 ? Vec3(n / len) : Vec3(-world_from_view_for(v).col(1));
}

}  // namespace

BlendEngine::BlendEngine(const MapSet& maps, const ViewSet& view_set, const BlendRule& rule)
    : maps_(maps), view_set_(view_set), rule_(rule), cache_(std::make_unique<Cache>()) {
  check_blend_inputs(maps, view_set);
  cache_->sources.resize(maps.views.size());
  cache_->once = std::make_unique<std::once_flag[]>(maps.views.size());
  cache_->pyramid_once = std::make_unique<std::once_flag[]>(maps.views.size());
  // Native sizes (core/resolution_mask.h): the level from which each map holds real detail.
  for (std::size_t i = 0; i < maps.views.size(); ++i) {
    try {
      detail_levels_.push_back(native_detail_level(maps.views[i]));
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument("blend: view " + std::to_string(i) + ": " + e.what());
    }
  }
  mixed_ = rsibr::mixed_resolution(detail_levels_);
  const auto& views = view_set.views();
  for (const auto& T : view_set.triangles()) {
    const Vec3 &a = views[std::size_t(T[0])], &b = views[std::size_t(T[1])], &c = views[std::size_t(T[2])];
    edge_norms_.push_back({a.cross(b).norm(), b.cross(c).norm(), c.cross(a).norm()});
  }
}

BlendEngine::~BlendEngine() = default;

const BlendEngine::Source& BlendEngine::source(int index) const {
  const std::size_t i = std::size_t(index);
  std::call_once(cache_->once[i], [&] {
    check_blend_source(maps_, index);
    cache_->sources[i] = std::make_unique<Source>(make_source(maps_.views[i], rule_.use_confidence));
  });
  return *cache_->sources[i];
}

const BlendEngine::Source& BlendEngine::source_pyramid(int index) const {
  const Source& s = source(index);
  const std::size_t i = std::size_t(index);
  std::call_once(cache_->pyramid_once[i], [&] {
    Source& own = *cache_->sources[i];
    build_levels(own);
    if (mixed_) own.mask = make_mask(own, detail_levels_[i]);
  });
  return s;
}

void BlendEngine::prepare_all() const {
  for (std::size_t i = 0; i < maps_.views.size(); ++i) source(int(i));
}

ViewWeights BlendEngine::locate(const Vec3& v, int* hint) const {
  if (hint && *hint >= 0 && std::size_t(*hint) < view_set_.triangles().size() && v.allFinite() &&
      v.cwiseAbs().maxCoeff() > 0) {
    const auto& T = view_set_.triangles()[std::size_t(*hint)];
    const auto& views = view_set_.views();
    const Vec3 &a = views[std::size_t(T[0])], &b = views[std::size_t(T[1])], &c = views[std::size_t(T[2])];
    const Vec3 p = unit(v);
    // The triangles of a view set do not overlap, so a point this far inside one is in no other.
    constexpr double kInside = 1e-9;
    const auto& e = edge_norms_[std::size_t(*hint)];
    if (det3(a, b, p) > kInside * e[0] && det3(b, c, p) > kInside * e[1] && det3(c, a, p) > kInside * e[2]) {
      ViewWeights out;
      out.count = 3;
      out.views = T;
      out.weights = triangle_weights(p, a, b, c, rule_.barycentric);
      out.triangle = *hint;
      out.inside = true;
      out.distance = 0;
      return out;
    }
  }
  ViewWeights out = view_set_.locate(v, rule_.barycentric);
  if (hint) *hint = out.triangle;
  return out;
}

Vec3 BlendEngine::radiance(const ViewWeights& located, const Vec3& v, const Vec3& n, const Footprint& footprint,
                           double* weight) const {
  if (!mixed_ && footprint.dn_dx.isZero(0) && footprint.dn_dy.isZero(0)) return radiance(located, v, n, weight);
  return radiance_at(located, v, n, &footprint, weight);
}

Vec3 BlendEngine::radiance_at(const ViewWeights& located, const Vec3& v, const Vec3& n_in, const Footprint* fp,
                              double* weight) const {
  double nv;
  const Vec3 n = normal_facing(n_in, v, &nv);
  const Vec3 r = 2.0 * nv * n - v;
  const std::vector<float>& albedo = maps_.views.front().albedo;
  const Vec3 A = albedo.empty() ? Vec3(1, 1, 1) : albedo_at(albedo, float(nv));
  // The footprint's corners: the central directions of n + dn_dx and n + dn_dy.
  const bool has_footprint = fp && !(fp->dn_dx.isZero(0) && fp->dn_dy.isZero(0));
  Vec3 corner_n[2], corner_r[2];
  if (has_footprint)
    for (int q = 0; q < 2; ++q) {
      Vec3 m = (n + (q == 0 ? fp->dn_dx : fp->dn_dy));
      m = m.norm() > 0 ? Vec3(m.normalized()) : n;
      corner_n[q] = m;
      corner_r[q] = 2.0 * std::max(0.0, m.dot(v)) * m - v;
    }

  const Source* sources[3];
  WarpSample samples[3];
  float a[3] = {0, 0, 0}, mask[3] = {0, 0, 0};
  double lod[3] = {0, 0, 0};
  const float inv_fade = rule_.rim_fade > 0 ? float(1.0 / rule_.rim_fade) : 0.0f;
  float mask_max = 0.0f;
  for (int k = 0; k < located.count; ++k) {
    const int index = located.views[std::size_t(k)];
    const Source& s = has_footprint || mixed_ ? source_pyramid(index) : source(index);
    sources[k] = &s;
    const bool mirror = s.kind == CentralDirection::Mirror;
    samples[k] = warp_direction(s.kind, s.view_from_world * (mirror ? r : n));
    if (has_footprint) {
      const WarpSample q1 = warp_direction(s.kind, s.view_from_world * (mirror ? corner_r[0] : corner_n[0]));
      const WarpSample q2 = warp_direction(s.kind, s.view_from_world * (mirror ? corner_r[1] : corner_n[1]));
      lod[k] = lod_of(samples[k].disc, q1.disc, q2.disc, s.width);
    }
    const double w = located.weights[std::size_t(k)];
    if (!(w > 0)) continue;
    a[k] = faded(float(w), float(samples[k].rim), inv_fade);
    if (mixed_ && a[k] > 0.0f) {
      mask[k] = s.mask->sample(sphere_map::pixel_from_disc(samples[k].disc, s.width, s.height), lod[k]);
      mask_max = std::max(mask_max, mask[k]);
    }
  }
  v4f acc = {0.0f, 0.0f, 0.0f, 0.0f};
  for (int k = 0; k < located.count; ++k) {
    float ak = a[k];
    if (mixed_) ak *= mask[k] + 1.0f - mask_max;  // the MIP-mask blend's s_k
    if (!(ak > 0.0f)) continue;
    contribute_lod(*sources[k], ak, float(samples[k].disc.x()), float(samples[k].disc.y()), lod[k], acc);
  }
  float out[3], total = 0;
  if (!finish(acc, out, &total))
    fallback(
        sources, located.count, [&](int k) { return samples[k]; }, out);
  if (weight) *weight = total;
  return Vec3(out[0], out[1], out[2]).cwiseProduct(A);
}

BlendResult BlendEngine::mixed_map(const Vec3& view_dir, const Vec3& up, int W, int H) const {
  BlendResult result;
  result.world_from_view = world_from_view_for(view_dir, up);
  result.located = locate(view_dir);
  const Mat3& T = result.world_from_view;
  const Vec3 d = view_dir.normalized();
  result.rgb = cv::Mat::zeros(H, W, CV_32FC3);
  result.weight = cv::Mat::zeros(H, W, CV_32FC1);
  tbb::parallel_for(tbb::blocked_range<int>(0, H), [&](const tbb::blocked_range<int>& rows) {
    for (int r = rows.begin(); r != rows.end(); ++r) {
      const auto [c0, c1] = disc_span(r, W, H);
      for (int c = c0; c < c1; ++c) {
        // The destination texel's footprint: its neighbours' normals one texel right and down.
        const Vec2 xy = sphere_map::disc_from_pixel(Vec2(c, r), W, H);
        const Vec3 n = T * sphere_map::g_normal(xy);
        Footprint fp;
        fp.dn_dx = T * sphere_map::g_normal(xy + Vec2(2.0 / W, 0)) - n;
        fp.dn_dy = T * sphere_map::g_normal(xy - Vec2(0, 2.0 / H)) - n;
        double w = 0;
        const Vec3 L = radiance_at(result.located, d, n, &fp, &w);
        float* o = result.rgb.ptr<float>(r) + 3 * c;
        o[0] = float(L.x());
        o[1] = float(L.y());
        o[2] = float(L.z());
        result.weight.at<float>(r, c) = float(w);
      }
    }
  });
  return result;
}

Vec3 BlendEngine::radiance(const ViewWeights& located, const Vec3& v, const Vec3& n_in, double* weight) const {
  if (mixed_) return radiance_at(located, v, n_in, nullptr, weight);
  double nv;
  const Vec3 n = normal_facing(n_in, v, &nv);
  const Vec3 r = 2.0 * nv * n - v;
  // Albedo-normalised sets: the blend of stored texels times A(n.v) (core/albedo_normalisation.h).
  const std::vector<float>& albedo = maps_.views.front().albedo;
  const Vec3 A = albedo.empty() ? Vec3(1, 1, 1) : albedo_at(albedo, float(nv));

  const Source* sources[3];
  WarpSample samples[3];
  const float inv_fade = rule_.rim_fade > 0 ? float(1.0 / rule_.rim_fade) : 0.0f;
  v4f acc = {0.0f, 0.0f, 0.0f, 0.0f};
  for (int k = 0; k < located.count; ++k) {
    const Source& s = source(located.views[std::size_t(k)]);
    sources[k] = &s;
    samples[k] = warp_direction(s.kind, s.view_from_world * (s.kind == CentralDirection::Mirror ? r : n));
    const double w = located.weights[std::size_t(k)];
    if (!(w > 0)) continue;
    const float a = faded(float(w), float(samples[k].rim), inv_fade);
    if (!(a > 0.0f)) continue;
    const float x = float(samples[k].disc.x()), y = float(samples[k].disc.y());
    contribute(s, taps(s.grid, x, y, a), a, x, y, acc);
  }
  float out[3], total = 0;
  if (!finish(acc, out, &total))
    fallback(
        sources, located.count, [&](int k) { return samples[k]; }, out);
  if (weight) *weight = total;
  return Vec3(out[0], out[1], out[2]).cwiseProduct(A);
}

BlendResult BlendEngine::map(const Vec3& view_dir, const Vec3& up, const MapRequest& request) const {
  BlendResult result;
  map(view_dir, up, request, result);
  return result;
}

void BlendEngine::map(const Vec3& view_dir, const Vec3& up, const MapRequest& request, BlendResult& result) const {
  if (!view_dir.allFinite() || !(view_dir.norm() > 0))
    throw std::invalid_argument("blend: view direction must be finite and non-zero");
  if ((request.width > 0) != (request.height > 0) || request.width < 0 || request.height < 0)
    throw std::invalid_argument("blend: give both width and height (> 0), or neither");
  const int W = request.width > 0 ? request.width : maps_.width();
  const int H = request.height > 0 ? request.height : maps_.height();
  if (W < 1 || H < 1) throw std::invalid_argument("blend: empty destination size");
  static const ExactWarp exact;
  const Warp& warp = request.warp ? *request.warp : exact;
  if (!warp.supports(W, H))
    throw std::invalid_argument(std::string("blend: the ") + warp.name() + " warp does not support " +
                                std::to_string(W) + "x" + std::to_string(H));

  if (mixed_) {
    result = mixed_map(view_dir, up, W, H);
    return;
  }

  result.world_from_view = world_from_view_for(view_dir, up);
  result.located = locate(view_dir);
  const ViewWeights& located = result.located;
  const Mat3& T_d = result.world_from_view;
  const int n = located.count;
  const Source* sources[3] = {nullptr, nullptr, nullptr};
  Mat3 source_from_dest[3];
  int active[3], m = 0;
  for (int k = 0; k < n; ++k) {
    sources[k] = &source(located.views[std::size_t(k)]);
    source_from_dest[k] = sources[k]->view_from_world * T_d;
    if (located.weights[std::size_t(k)] > 0) active[m++] = k;
  }
  const float inv_fade = rule_.rim_fade > 0 ? float(1.0 / rule_.rim_fade) : 0.0f;
  // Per located source: the rotation in float (warp_directions' form) and the weight; which central
  // direction kinds the active sources use (computed once per destination row for all of them).
  float rotation[3][9], weight[3];
  bool kinds_used[2] = {false, false};
  for (int k = 0; k < n; ++k) {
    for (int i = 0; i < 9; ++i) rotation[k][i] = float(source_from_dest[k](i / 3, i % 3));
    weight[k] = float(located.weights[std::size_t(k)]);
  }
  for (int j = 0; j < m; ++j) kinds_used[int(sources[active[j]]->kind)] = true;

  result.rgb.create(H, W, CV_32FC3);
  result.weight.create(H, W, CV_32FC1);
  for (int k = 0; k < 3; ++k) {
    cv::Mat& sw = result.source_weight[std::size_t(k)];
    if (request.source_weights) {
      sw.create(H, W, CV_32FC1);
      sw.setTo(0.0f);
    } else {
      sw.release();
    }
  }

  // Tiles of kTileRows x kTileCols destination texels (whole rows up to 512 wide): the row loops run
  // long enough to amortise their set-up, and a row's taps in three sources (about 50 KiB at 512^2)
  // stay in the core's cache for the next row's. Per texel the arithmetic does not depend on the
  // tiling or the threads.
  constexpr int kTileRows = 8;
  // One tile: rows [r0, r1) (at most kTileRows), columns [cb, cb + kTileCols) cut to each row's disc
  // span (spans[r - r0]). Row by row: the central directions once (when the warp rotates them), then
  // source by source the warp, the footprints and the taps as row loops into the row's sums (so one
  // source's texels are read in one sweep; faster than all sources per texel with the sums in
  // registers), then the normalisation, and the fallback for the texels no source reached.
  const auto tile = [&](int r0, int r1, int cb, const std::pair<int, int>* spans) {
    v4f acc[kTileCols];
    float x[kTileCols], y[kTileCols], rim[kTileCols], a[kTileCols];
    float cx[2][kTileCols], cy[2][kTileCols], cz[2][kTileCols];  // central directions, per kind
    int missing[kTileCols];
    TapRows t;
    for (int r = r0; r < r1; ++r) {
      const int c0 = std::max(spans[r - r0].first, cb), c1 = std::min(spans[r - r0].second, cb + kTileCols);
      const int span = c1 - c0;
      if (span <= 0) continue;
      std::fill(acc, acc + span, v4f{0.0f, 0.0f, 0.0f, 0.0f});
      bool shared[2] = {false, false};
      for (int kind = 0; kind < 2; ++kind)
        if (kinds_used[kind])
          shared[kind] = warp.central_block(CentralDirection(kind), W, H, r, c0, c1, cx[kind], cy[kind], cz[kind]);
      for (int j = 0; j < m; ++j) {
        const int k = active[j];
        const Source& s = *sources[k];
        const int kind = int(s.kind);
        if (shared[kind])
          warp_directions(s.kind, rotation[k], span, cx[kind], cy[kind], cz[kind], x, y, rim);
        else
          warp.warp_block(s.kind, source_from_dest[k], W, H, r, c0, c1, x, y, rim);
        taps_row(s.grid, span, weight[k], inv_fade, x, y, rim, a, t);
        float* sw = request.source_weights ? result.source_weight[std::size_t(k)].ptr<float>(r) + c0 : nullptr;
        gather_row(s, span, a, x, y, t, acc, sw);
      }
      float* out = result.rgb.ptr<float>(r) + 3 * c0;
      const int count = finish_row(span, acc, out, result.weight.ptr<float>(r) + c0, missing);
      for (int q = 0; q < count; ++q) {
        const int i = missing[q];
        const Vec2 xy = sphere_map::disc_from_pixel(Vec2(c0 + i, r), W, H);
        fallback(
            sources, n,
            [&](int p) {
              return warp_direction(sources[p]->kind, source_from_dest[p] * central_direction(sources[p]->kind, xy));
            },
            out + 3 * i);
      }
    }
  };
  tbb::parallel_for(
      tbb::blocked_range<int>(0, H, kTileRows),
      [&](const tbb::blocked_range<int>& rows) {
        std::pair<int, int> spans[kTileRows];
        for (int r = rows.begin(); r != rows.end(); ++r) {
          const auto span = disc_span(r, W, H);
          spans[r - rows.begin()] = span;
          // Outside the disc: 0 (the outputs are not zero-initialised).
          float* o = result.rgb.ptr<float>(r);
          float* w = result.weight.ptr<float>(r);
          const int c0 = span.second > span.first ? span.first : W, c1 = span.second > span.first ? span.second : W;
          std::fill(o, o + 3 * c0, 0.0f);
          std::fill(o + 3 * c1, o + 3 * W, 0.0f);
          std::fill(w, w + c0, 0.0f);
          std::fill(w + c1, w + W, 0.0f);
        }
        for (int cb = 0; cb < W; cb += kTileCols) tile(rows.begin(), rows.end(), cb, spans);
      },
      tbb::simple_partitioner());

  // Albedo-normalised sets: the destination texel p has n.d = g_normal(p).z in d's own frame.
  const std::vector<float>& albedo = maps_.views.front().albedo;
  if (!albedo.empty()) denormalise_by_albedo(result.rgb, albedo);
}

}  // namespace rsibr
