// The blend's tile path as it was before the blend engine (runtime/blend_engine.h), frozen as the
// baseline of bench/blend_bench.cpp: warp in double (exact warps computed in the loop, any other
// warp through Warp::warp_row), taps from the 3-channel maps with per-row column tables, sums in
// float. Not used by rsibr itself; kept so that the engine's speed-up is measured in the same run.
#include "previous_blend.h"

#include "core/avx2_clones.h"
#include "core/sphere_map.h"
#include "runtime/disc_sampler.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

namespace rsibr::previous {

namespace {

RSIBR_AVX2_CLONES void central_directions_row(CentralDirection kind, int width, int height, int row, int c_begin,
                                              int c_end, double* __restrict out_x, double* __restrict out_y,
                                              double* __restrict out_z) {
  const double y = 1.0 - (2.0 * row + 1.0) / height;
  const int n = c_end - c_begin;
  for (int i = 0; i < n; ++i) {
    const double x = (2.0 * (c_begin + i) + 1.0) / width - 1.0;
    const double z = std::sqrt(std::max(0.0, 1.0 - (x * x + y * y)));  // g_normal inside the disc
    if (kind == CentralDirection::Mirror) {
      out_x[i] = 2 * x * z;
      out_y[i] = 2 * y * z;
      out_z[i] = 2 * z * z - 1.0;
    } else {
      out_x[i] = x;
      out_y[i] = y;
      out_z[i] = z;
    }
  }
}

// Branch-free forms of mirror_inverse / normal_inverse (selects, not jumps, so the loops vectorise).
// Also built for AVX2 (4 doubles a vector; chosen at load time where the CPU has it). No FMA: the
// results are the same to the bit on either path.
RSIBR_AVX2_CLONES void warp_directions(CentralDirection kind, const double m[9], int n, const double* __restrict x,
                                       const double* __restrict y, const double* __restrict z,
                                       double* __restrict disc_x, double* __restrict disc_y, double* __restrict rim) {
  const double m0 = m[0], m1 = m[1], m2 = m[2], m3 = m[3], m4 = m[4], m5 = m[5], m6 = m[6], m7 = m[7], m8 = m[8];
  if (kind == CentralDirection::Mirror) {
    for (int i = 0; i < n; ++i) {
      const double rx = m0 * x[i] + m1 * y[i] + m2 * z[i];
      const double ry = m3 * x[i] + m4 * y[i] + m5 * z[i];
      const double rz = m6 * x[i] + m7 * y[i] + m8 * z[i];
      const double q = rx * rx + ry * ry;
      // 1 + r_z, computed as q / (1 - r_z) where it cancels (r_z < 0); 1 + |r_z| >= 1 never divides by 0.
      const double one_plus_z = rz >= 0.0 ? 1.0 + rz : q / (1.0 + std::abs(rz));
      const double h2 = q + one_plus_z * one_plus_z;
      const bool singular = !(h2 > 0.0);
      const double inv = 1.0 / std::sqrt(singular ? 1.0 : h2);
      disc_x[i] = singular ? 0.0 : rx * inv;
      disc_y[i] = singular ? -1.0 : ry * inv;
      rim[i] = singular ? 0.0 : one_plus_z * inv;
    }
  } else {
    for (int i = 0; i < n; ++i) {
      const double nx = m0 * x[i] + m1 * y[i] + m2 * z[i];
      const double ny = m3 * x[i] + m4 * y[i] + m5 * z[i];
      const double nz = m6 * x[i] + m7 * y[i] + m8 * z[i];
      // Behind the visible hemisphere: the nearest rim point ((0, -1) straight behind).
      const double l2 = nx * nx + ny * ny;
      const bool behind = nz < 0.0;
      const bool straight = !(l2 > 0.0);
      const double inv = 1.0 / std::sqrt(straight ? 1.0 : l2);
      const double s = behind ? inv : 1.0;
      const bool fixed = behind & straight;
      disc_x[i] = fixed ? 0.0 : nx * s;
      disc_y[i] = fixed ? -1.0 : ny * s;
      rim[i] = nz;
    }
  }
}

// One located source, ready to sample.
struct Source : DiscMap {
  CentralDirection kind = CentralDirection::Mirror;
  Mat3 source_from_dest = Mat3::Identity();
  double weight = 0;  // barycentric
};

bool sample(const Source& s, const Vec2& xy, double rgb[3], double* confidence) {
  return sample_disc(s, xy, rgb, confidence);
}

// The fast path's view of a source: rotation and pixel mapping; per source row, the columns
// whose texel centres lie inside the disc (sample_disc's tap test, the same double arithmetic), so
// that a bilinear footprint with all four taps valid is recognised with four compares; and a disc
// radius inside which every footprint has its four taps valid, so that most texels need no compare.
struct FastSource {
  const float* rgb = nullptr;
  const float* confidence = nullptr;
  int rgb_step = 0, confidence_step = 0;  // in floats
  int width = 0, height = 0;
  double m[9] = {};
  double weight = 0;
  double scale_x = 0, offset_x = 0, scale_y = 0, offset_y = 0;  // pixel = (x scale_x + offset_x, offset_y - y scale_y)
  double interior2 = -1;                                        // squared disc radius of the interior
  std::vector<int> lo, hi;                                      // per row: valid tap columns [lo, hi)
};

void prepare(const Source& s, FastSource& f) {
  f.rgb = s.rgb->ptr<float>(0);
  f.rgb_step = int(s.rgb->step1());
  if (s.confidence) {
    f.confidence = s.confidence->ptr<float>(0);
    f.confidence_step = int(s.confidence->step1());
  }
  f.width = s.width;
  f.height = s.height;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) f.m[3 * i + j] = s.source_from_dest(i, j);
  f.weight = s.weight;
  f.scale_x = 0.5 * s.width;
  f.offset_x = 0.5 * (s.width - 1);
  f.scale_y = 0.5 * s.height;
  f.offset_y = 0.5 * (s.height - 1);
  // A footprint's taps lie within one texel of the point in x and in y, and the gather loop also
  // reads the first channel of the texel right of the footprint (4-wide loads): within a disc-unit
  // distance sqrt((4/W)^2 + (2/H)^2). Points inside radius 1 - that (less a margin for rounding)
  // have all of these inside the disc and in the image. Offsets must fit an int (else no interior).
  const double reach = std::sqrt(16.0 / (double(s.width) * s.width) + 4.0 / (double(s.height) * s.height));
  const double radius = 1.0 - reach - 1e-4;
  const bool fits =
      double(s.rgb->step1()) * s.height < 2e9 && (!s.confidence || double(s.confidence->step1()) * s.height < 2e9);
  f.interior2 = radius > 0 && fits ? radius * radius : -1.0;
  f.lo.assign(std::size_t(s.height), s.width);
  f.hi.assign(std::size_t(s.height), 0);
  for (int r = 0; r < s.height; ++r) {
    const double y = 1.0 - (2.0 * r + 1.0) / s.height;  // sample_disc's tap test
    const auto inside = [&](int c) {
      const double x = (2.0 * c + 1.0) / s.width - 1.0;
      return !(x * x + y * y > 1.0);
    };
    if (!(y * y <= 1.0)) continue;
    const double half = std::sqrt(1.0 - y * y);
    int c0 = std::clamp(int(std::floor(0.5 * ((1.0 - half) * s.width - 1.0))), 0, s.width);
    while (c0 > 0 && inside(c0 - 1)) --c0;
    while (c0 < s.width && !inside(c0)) ++c0;
    if (c0 == s.width) continue;
    int c1 = std::clamp(int(std::ceil(0.5 * ((1.0 + half) * s.width - 1.0))) + 1, c0 + 1, s.width);
    while (c1 < s.width && inside(c1)) ++c1;
    while (c1 > c0 && !inside(c1 - 1)) --c1;
    f.lo[std::size_t(r)] = c0;
    f.hi[std::size_t(r)] = c1;
  }
}

// Four floats (GCC/Clang vector extension): one bilinear tap's RGB in one load.
typedef float v4f __attribute__((vector_size(16)));
inline v4f load4(const float* p) {
  v4f v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

// Per-tile-row scratch of the fast path, structure of arrays (one allocation per task).
struct Scratch {
  std::vector<double> doubles;
  std::vector<float> floats;
  std::vector<int> ints;
  std::vector<WarpSample> samples;
  double *dir[2][3], *disc_x[3], *disc_y[3], *rim[3];
  float *a[3], *fx[3], *fy[3], *acc[4];
  int *offset[3], *conf_offset[3], *interior[3];
  explicit Scratch(int width)
      : doubles(std::size_t(15) * std::size_t(width)),
        floats(std::size_t(13) * std::size_t(width)),
        ints(std::size_t(9) * std::size_t(width)) {
    double* p = doubles.data();
    float* q = floats.data();
    for (auto& d : dir)
      for (auto& c : d) c = p, p += width;
    acc[3] = q, q += width;
    for (int k = 0; k < 3; ++k) {
      disc_x[k] = p, p += width;
      disc_y[k] = p, p += width;
      rim[k] = p, p += width;
      a[k] = q, q += width;
      fx[k] = q, q += width;
      fy[k] = q, q += width;
      acc[k] = q, q += width;
      offset[k] = ints.data() + std::size_t(3 * k) * std::size_t(width);
      conf_offset[k] = offset[k] + width;
      interior[k] = conf_offset[k] + width;
    }
  }
};

// a = weight * fade(rim) (rim_fade_weight's formula), rounded to float.
// Vectorised, also for AVX2 (as warp_directions, runtime/warp.cpp: no FMA, the same bits).
RSIBR_AVX2_CLONES void fade_row(int n, double weight, double rim_fade, const double* __restrict rim,
                                float* __restrict a) {
  if (!(rim_fade > 0)) {
    for (int i = 0; i < n; ++i) a[i] = float(weight);
    return;
  }
  const double inv = 1.0 / rim_fade;
  for (int i = 0; i < n; ++i) {
    const double rho = rim[i];
    const double t = std::min(rho * inv, 1.0);
    a[i] = float(rho > 0.0 ? weight * (t * t * (3.0 - 2.0 * t)) : 0.0);
  }
}

// The bilinear footprint of each disc point (vectorised): the offset of its top-left tap in floats
// (rgb; the confidence offset follows from it), the fractions, and whether it lies in the interior
// (all four taps valid: the gather loop needs no further test).
RSIBR_AVX2_CLONES void footprints_row(const FastSource& f, int n, const double* __restrict disc_x,
                                      const double* __restrict disc_y, float* __restrict fx, float* __restrict fy,
                                      int* __restrict offset, int* __restrict conf_offset, int* __restrict interior) {
  // Locals: the int stores below could otherwise alias f's members, which would then be reloaded.
  const double interior2 = f.interior2, scale_x = f.scale_x, offset_x = f.offset_x, scale_y = f.scale_y,
               offset_y = f.offset_y;
  const int rgb_step = f.rgb_step, confidence_step = f.confidence_step;
  for (int i = 0; i < n; ++i) {
    const double x = disc_x[i], y = disc_y[i];
    const bool in = x * x + y * y <= interior2;
    // Outside the interior the values are unused (the exact test and sample_disc decide there);
    // zero keeps the conversions in range.
    const double px = in ? x * scale_x + offset_x : 0.0;
    const double py = in ? offset_y - y * scale_y : 0.0;
    const int c0 = int(px), r0 = int(py);  // px, py >= 0 in the interior: truncation is floor
    fx[i] = float(px - c0);
    fy[i] = float(py - r0);
    offset[i] = r0 * rgb_step + 3 * c0;
    conf_offset[i] = r0 * confidence_step + c0;
    interior[i] = in;
  }
}

// out = acc / total (RGB interleaved), weight = total; where total is 0, 0 and 0 (the caller's
// fallback then decides).
void normalise_row(int n, const float* __restrict r, const float* __restrict g, const float* __restrict b,
                   const float* __restrict total, float* __restrict out, float* __restrict weight) {
  for (int i = 0; i < n; ++i) {
    const float t = total[i];
    const float inv = t > 0.0f ? 1.0f / t : 0.0f;
    out[3 * i] = r[i] * inv;
    out[3 * i + 1] = g[i] * inv;
    out[3 * i + 2] = b[i] * inv;
    weight[i] = t > 0.0f ? t : 0.0f;
  }
}

// One source's sample at a point outside the interior: bilinear in float when all four taps are
// valid (the per-row column tables), else sample_disc (the reference sampler). False: no sample.
bool sample_rim(const FastSource& f, const Source& ref, double x, double y, float L[3], float* confidence) {
  double px = x * f.scale_x + f.offset_x, py = f.offset_y - y * f.scale_y;
  px = px > -1.0 ? (px < f.width ? px : f.width) : -1.0;  // NaN -> -1
  py = py > -1.0 ? (py < f.height ? py : f.height) : -1.0;
  const int c0 = int(px + 1.0) - 1, r0 = int(py + 1.0) - 1;  // floor (px, py >= -1)
  if (r0 >= 0 && r0 + 1 < f.height && c0 >= f.lo[std::size_t(r0)] && c0 + 1 < f.hi[std::size_t(r0)] &&
      c0 >= f.lo[std::size_t(r0 + 1)] && c0 + 1 < f.hi[std::size_t(r0 + 1)]) {
    const float fx = float(px - c0), fy = float(py - r0);
    const float w00 = (1.0f - fx) * (1.0f - fy), w01 = fx * (1.0f - fy), w10 = (1.0f - fx) * fy, w11 = fx * fy;
    const float* t0 = f.rgb + std::size_t(r0) * std::size_t(f.rgb_step) + 3 * std::size_t(c0);
    const float* t1 = t0 + f.rgb_step;
    for (int j = 0; j < 3; ++j) L[j] = w00 * t0[j] + w01 * t0[3 + j] + w10 * t1[j] + w11 * t1[3 + j];
    *confidence = 1.0f;
    if (f.confidence) {
      const float* k0 = f.confidence + std::size_t(r0) * std::size_t(f.confidence_step) + std::size_t(c0);
      const float* k1 = k0 + f.confidence_step;
      // Normalised by the weights' sum, as sample_disc: exactly 1 for a confidence of 1.
      const float c = (w00 * k0[0] + w01 * k0[1] + w10 * k1[0] + w11 * k1[1]) / (w00 + w01 + w10 + w11);
      *confidence = c > 0.0f ? c : 0.0f;  // negative or NaN counts as 0
    }
    return true;
  }
  double Ld[3], conf;
  if (!sample_disc(ref, Vec2(x, y), Ld, &conf)) return false;
  for (int j = 0; j < 3; ++j) L[j] = float(Ld[j]);
  *confidence = float(conf);
  return true;
}

// The fallback of step 5 for one texel (rare): the least-faded located source, weight 0.
void fallback(const Source* sources, int n, int W, int H, int r, int c, float* o) {
  const Vec2 xy = sphere_map::disc_from_pixel(Vec2(c, r), W, H);
  int best = -1;
  WarpSample best_sample;
  for (int k = 0; k < n; ++k) {
    const WarpSample ws =
        warp_direction(sources[k].kind, sources[k].source_from_dest * central_direction(sources[k].kind, xy));
    if (best < 0 || ws.rim > best_sample.rim) {
      best = k;
      best_sample = ws;
    }
  }
  double L[3], conf;
  if (best >= 0 && sample(sources[best], best_sample.disc, L, &conf)) {
    o[0] = float(L[0]);
    o[1] = float(L[1]);
    o[2] = float(L[2]);
  }
}

}  // namespace

BlendResult blend(const MapSet& maps, const ViewSet& view_set, const Vec3& view_dir, const Vec3& up,
                  const BlendOptions& options) {
  if (!view_dir.allFinite() || !(view_dir.norm() > 0))
    throw std::invalid_argument("blend: view direction must be finite and non-zero");
  if ((options.width > 0) != (options.height > 0) || options.width < 0 || options.height < 0)
    throw std::invalid_argument("blend: give both width and height (> 0), or neither");
  const int W = options.width > 0 ? options.width : maps.width();
  const int H = options.height > 0 ? options.height : maps.height();
  if (W < 1 || H < 1) throw std::invalid_argument("blend: empty destination size");
  static const ExactWarp exact;
  const Warp& warp = options.warp ? *options.warp : exact;
  if (!warp.supports(W, H))
    throw std::invalid_argument(std::string("blend: the ") + warp.name() + " warp does not support " +
                                std::to_string(W) + "x" + std::to_string(H));

  BlendResult result;
  result.world_from_view = world_from_view_for(view_dir, up);
  result.located = view_set.locate(view_dir, options.barycentric);
  const ViewWeights& located = result.located;
  const Mat3& T_d = result.world_from_view;

  const int n = located.count;
  Source sources[3];
  for (int k = 0; k < n; ++k) {
    const int index = located.views[std::size_t(k)];
    check_blend_source(maps, index);
    const MapView& v = maps.views[std::size_t(index)];
    Source& s = sources[k];
    s.rgb = &v.rgb;
    s.confidence = options.use_confidence && !v.confidence.empty() ? &v.confidence : nullptr;
    s.width = v.rgb.cols;
    s.height = v.rgb.rows;
    s.kind = v.warp;
    s.source_from_dest = v.world_from_view.transpose() * T_d;
    s.weight = located.weights[std::size_t(k)];
  }

  result.rgb.create(H, W, CV_32FC3);
  result.weight.create(H, W, CV_32FC1);
  if (options.source_weights)
    for (int k = 0; k < 3; ++k) result.source_weight[std::size_t(k)] = cv::Mat::zeros(H, W, CV_32FC1);

  // The fast path: structure of arrays, one fused pass per tile
  // row (warp and fade in double, footprints, float taps and sums, normalisation), bands of rows in
  // parallel. Per texel the arithmetic does not depend on the tiling or the threads.
  FastSource fast[3];
  bool kinds[2] = {false, false};
  for (int k = 0; k < n; ++k) {
    if (!(sources[k].weight > 0)) continue;
    prepare(sources[k], fast[k]);
    kinds[int(sources[k].kind)] = true;
  }
  const bool fused = std::string(warp.name()) == "exact" || std::string(warp.name()) == "precomputed";
  bool any_confidence = false;
  for (int k = 0; k < n; ++k) any_confidence = any_confidence || fast[k].confidence;
  // One fused pass over destination texels (r, c), c in [c0, c1) (at most the scratch's width):
  // vectorised warp, fade and footprints per source, then one gather loop over the texels.
  const auto tile_row = [&](int r, int c0, int c1, Scratch& s) {
    const int span = c1 - c0;
    if (fused)
      for (int kind = 0; kind < 2; ++kind)
        if (kinds[kind])
          central_directions_row(CentralDirection(kind), W, H, r, c0, c1, s.dir[kind][0], s.dir[kind][1],
                                 s.dir[kind][2]);
    int active[3], m = 0;
    for (int k = 0; k < n; ++k) {
      const Source& src = sources[k];
      if (!(src.weight > 0)) continue;
      active[m++] = k;
      if (fused) {
        double* const* d = s.dir[int(src.kind)];
        warp_directions(src.kind, fast[k].m, span, d[0], d[1], d[2], s.disc_x[k], s.disc_y[k], s.rim[k]);
      } else {
        if (s.samples.size() < std::size_t(span)) s.samples.resize(std::size_t(span));
        warp.warp_row(src.kind, src.source_from_dest, W, H, r, c0, c1, s.samples.data());
        for (int i = 0; i < span; ++i) {
          s.disc_x[k][i] = s.samples[std::size_t(i)].disc.x();
          s.disc_y[k][i] = s.samples[std::size_t(i)].disc.y();
          s.rim[k][i] = s.samples[std::size_t(i)].rim;
        }
      }
      fade_row(span, fast[k].weight, options.rim_fade, s.rim[k], s.a[k]);
      footprints_row(fast[k], span, s.disc_x[k], s.disc_y[k], s.fx[k], s.fy[k], s.offset[k], s.conf_offset[k],
                     s.interior[k]);
    }
    float* out = result.rgb.ptr<float>(r) + 3 * c0;
    float* out_w = result.weight.ptr<float>(r) + c0;
    float* sw[3] = {nullptr, nullptr, nullptr};
    if (options.source_weights)
      for (int k = 0; k < 3; ++k) sw[k] = result.source_weight[std::size_t(k)].ptr<float>(r) + c0;
    // The gathers are latency-bound (the source rows a tile needs are seldom in cache yet): the taps
    // kPrefetch texels ahead are requested early (a prefetch never faults).
    constexpr int kPrefetch = 12;
    for (int i = 0; i < span; ++i) {
      if (i + kPrefetch < span)
        for (int j = 0; j < m; ++j) {
          const int k = active[j];
          const float* t = fast[k].rgb + s.offset[k][i + kPrefetch];  // offset 0 outside the interior
          __builtin_prefetch(t);
          __builtin_prefetch(t + fast[k].rgb_step);
        }
      v4f acc = {0.0f, 0.0f, 0.0f, 0.0f};
      float total = 0;
      for (int j = 0; j < m; ++j) {
        const int k = active[j];
        float a = s.a[k][i];
        if (!(a > 0.0f)) continue;
        const FastSource& f = fast[k];
        v4f L;
        if (s.interior[k][i]) {
          const float fx = s.fx[k][i], fy = s.fy[k][i];
          const float w00 = (1.0f - fx) * (1.0f - fy), w01 = fx * (1.0f - fy), w10 = (1.0f - fx) * fy, w11 = fx * fy;
          const float* t0 = f.rgb + s.offset[k][i];
          const float* t1 = t0 + f.rgb_step;
          // Four lanes: RGB and the next texel's R (unused; in the image, see FastSource::interior2).
          L = w00 * load4(t0) + w01 * load4(t0 + 3) + w10 * load4(t1) + w11 * load4(t1 + 3);
          if (any_confidence && f.confidence) {
            const float* k0 = f.confidence + s.conf_offset[k][i];
            const float* k1 = k0 + f.confidence_step;
            // Normalised by the weights' sum, as sample_disc: exactly 1 for a confidence of 1.
            const float conf = (w00 * k0[0] + w01 * k0[1] + w10 * k1[0] + w11 * k1[1]) / (w00 + w01 + w10 + w11);
            a *= conf > 0.0f ? conf : 0.0f;  // negative or NaN counts as 0
          }
        } else {
          float conf, Lr[3];
          if (!sample_rim(f, sources[k], s.disc_x[k][i], s.disc_y[k][i], Lr, &conf)) continue;
          a *= conf;
          L = v4f{Lr[0], Lr[1], Lr[2], 0.0f};
        }
        if (!(a > 0.0f)) continue;
        acc += a * L;
        total += a;
        if (sw[k]) sw[k][i] = a;
      }
      s.acc[0][i] = acc[0];
      s.acc[1][i] = acc[1];
      s.acc[2][i] = acc[2];
      s.acc[3][i] = total;
    }
    // Normalisation (vectorised), then the fallback where nothing was accumulated.
    normalise_row(span, s.acc[0], s.acc[1], s.acc[2], s.acc[3], out, out_w);
    int empty = 0;
    for (int i = 0; i < span; ++i) empty += !(s.acc[3][i] > 0.0f);
    const bool any_empty = empty > 0;
    if (any_empty)
      for (int i = 0; i < span; ++i)
        if (!(s.acc[3][i] > 0.0f)) {
          float* o = out + 3 * i;
          o[0] = o[1] = o[2] = 0.0f;
          fallback(sources, n, W, H, r, c0 + i, o);
          out_w[i] = 0.0f;
        }
  };
  // Tiles of kTileRows x kTileCols destination texels: a tile's footprint in each source is compact
  // (tens of KiB for three sources), so the bilinear taps hit the cache and the TLB; a whole
  // destination row sweeps a curve across hundreds of source rows.
  constexpr int kTileRows = 16, kTileCols = 64;
  tbb::parallel_for(
      tbb::blocked_range<int>(0, H, kTileRows),
      [&](const tbb::blocked_range<int>& rows) {
        Scratch s(kTileCols);
        std::pair<int, int> spans[kTileRows];
        for (int r = rows.begin(); r != rows.end(); ++r) {
          const auto span = disc_span(r, W, H);
          spans[r - rows.begin()] = span;
          // Outside the disc: 0 (the outputs are not zero-initialised on this path).
          float* o = result.rgb.ptr<float>(r);
          float* w = result.weight.ptr<float>(r);
          const int c0 = span.second > span.first ? span.first : W, c1 = span.second > span.first ? span.second : W;
          std::fill(o, o + 3 * c0, 0.0f);
          std::fill(o + 3 * c1, o + 3 * W, 0.0f);
          std::fill(w, w + c0, 0.0f);
          std::fill(w + c1, w + W, 0.0f);
        }
        for (int cb = 0; cb < W; cb += kTileCols)
          for (int r = rows.begin(); r != rows.end(); ++r) {
            const int c0 = std::max(spans[r - rows.begin()].first, cb);
            const int c1 = std::min(spans[r - rows.begin()].second, cb + kTileCols);
            if (c1 > c0) tile_row(r, c0, c1, s);
          }
      },
      tbb::simple_partitioner());
  return result;
}

}  // namespace rsibr::previous
