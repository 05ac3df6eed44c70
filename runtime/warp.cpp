#include "runtime/warp.h"

#include "core/avx2_clones.h"
#include "core/sphere_map.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace rsibr {

Vec3 central_direction(CentralDirection kind, const Vec2& xy) {
  return kind == CentralDirection::Mirror ? sphere_map::g_mirror(xy) : sphere_map::g_normal(xy);
}

// g_mirror^-1 with the half vector's z as the rim value:
//   h = (r + z)/|r + z|,  disc = (h_x, h_y),  rim = h_z = sin(phi/2), phi = angle(r, -z).
// 1 + r_z cancels for r_z < 0, so it is computed as (r_x^2 + r_y^2)/(1 - r_z) (|r| = 1); the same
// operations as sphere_map::g_mirror_inv, so the disc point is bitwise equal to it.
static inline WarpSample mirror_inverse(const Vec3& r_in) {
  const double len = r_in.norm();
  if (!(len > 0) || !std::isfinite(len)) return {Vec2(0, 0), 0.0};
  const Vec3 r = r_in / len;
  const double q = r.x() * r.x() + r.y() * r.y();
  const double one_plus_z = r.z() >= 0 ? 1.0 + r.z() : q / (1.0 - r.z());
  const double hlen = std::sqrt(q + one_plus_z * one_plus_z);
  if (!(hlen > 0)) return {Vec2(0, -1), 0.0};  // r = -z exactly: the singular direction
  return {Vec2(r.x() / hlen, r.y() / hlen), one_plus_z / hlen};
}

// g_normal^-1 with n.z/|n| as the rim value; n.z < 0 goes to the nearest rim point.
static inline WarpSample normal_inverse(const Vec3& n) {
  const double len = n.norm();
  if (!(len > 0) || !std::isfinite(len)) return {Vec2(0, 0), 0.0};
  Vec2 xy(n.x() / len, n.y() / len);
  const double rim = n.z() / len;
  if (n.z() < 0) {
    const double l2 = xy.squaredNorm();
    xy = l2 > 0 ? Vec2(xy / std::sqrt(l2)) : Vec2(0, -1);  // straight behind: a fixed rim point
  }
  return {xy, rim};
}

WarpSample warp_direction(CentralDirection kind, const Vec3& dir_in_source) {
  return kind == CentralDirection::Mirror ? mirror_inverse(dir_in_source) : normal_inverse(dir_in_source);
}

// The inside test is monotone in |x| along a row, so the span is found from the analytic guess
// x^2 <= 1 - y^2 and then corrected by the exact test (a few steps at most).
std::pair<int, int> disc_span(int row, int width, int height) {
  const auto inside = [&](int c) {
    return sphere_map::disc_from_pixel(Vec2(c, row), width, height).squaredNorm() <= 1.0;
  };
  const double y = sphere_map::disc_from_pixel(Vec2(0, row), width, height).y();
  if (!(y * y <= 1.0)) return {0, 0};
  const double half = std::sqrt(1.0 - y * y);  // |x| <= half inside
  // c with (2c + 1)/width - 1 = -half, clamped to the row.
  int c0 = std::clamp(int(std::floor(0.5 * ((1.0 - half) * width - 1.0))), 0, width);
  while (c0 > 0 && inside(c0 - 1)) --c0;
  while (c0 < width && !inside(c0)) ++c0;
  if (c0 == width) return {0, 0};
  int c1 = std::clamp(int(std::ceil(0.5 * ((1.0 + half) * width - 1.0))) + 1, c0 + 1, width);
  while (c1 < width && inside(c1)) ++c1;
  while (c1 > c0 && !inside(c1 - 1)) --c1;
  return {c0, c1};
}

// Computed in double and rounded once: for texels near the rim, z = sqrt(1 - x^2 - y^2) cancels, and
// float's x alone would move z (and the mirror direction) by ~1e-5 at 129^2.
RSIBR_AVX512_CLONES void central_directions_row(CentralDirection kind, int width, int height, int row, int c_begin,
                                                int c_end, float* __restrict out_x, float* __restrict out_y,
                                                float* __restrict out_z) {
  const double y = 1.0 - (2.0 * row + 1.0) / height;
  const double inv_w = 1.0 / width;
  const int n = c_end - c_begin;
  for (int i = 0; i < n; ++i) {
    const double x = (2.0 * (c_begin + i) + 1.0) * inv_w - 1.0;
    const double z = std::sqrt(std::max(0.0, 1.0 - (x * x + y * y)));  // g_normal inside the disc
    if (kind == CentralDirection::Mirror) {
      out_x[i] = float(2 * x * z);
      out_y[i] = float(2 * y * z);
      out_z[i] = float(2 * z * z - 1.0);
    } else {
      out_x[i] = float(x);
      out_y[i] = float(y);
      out_z[i] = float(z);
    }
  }
}

// Branch-free forms of mirror_inverse / normal_inverse (selects, not jumps, so the loops vectorise).
// Also built for AVX2 (8 floats a vector; chosen at load time where the CPU has it). No FMA: the
// results are the same to the bit on either path.
RSIBR_AVX512_CLONES void warp_directions(CentralDirection kind, const float m[9], int n, const float* __restrict x,
                                         const float* __restrict y, const float* __restrict z, float* __restrict disc_x,
                                         float* __restrict disc_y, float* __restrict rim) {
  const float m0 = m[0], m1 = m[1], m2 = m[2], m3 = m[3], m4 = m[4], m5 = m[5], m6 = m[6], m7 = m[7], m8 = m[8];
  if (kind == CentralDirection::Mirror) {
    for (int i = 0; i < n; ++i) {
      const float rx = m0 * x[i] + m1 * y[i] + m2 * z[i];
      const float ry = m3 * x[i] + m4 * y[i] + m5 * z[i];
      const float rz = m6 * x[i] + m7 * y[i] + m8 * z[i];
      const float q = rx * rx + ry * ry;
      // 1 + r_z, computed as q / (1 - r_z) where it cancels (r_z < 0); 1 + |r_z| >= 1 never divides by 0.
      const float one_plus_z = rz >= 0.0f ? 1.0f + rz : q / (1.0f + std::abs(rz));
      const float h2 = q + one_plus_z * one_plus_z;
      const bool singular = !(h2 > 0.0f);
      const float inv = 1.0f / std::sqrt(singular ? 1.0f : h2);
      disc_x[i] = singular ? 0.0f : rx * inv;
      disc_y[i] = singular ? -1.0f : ry * inv;
      rim[i] = singular ? 0.0f : one_plus_z * inv;
    }
  } else {
    for (int i = 0; i < n; ++i) {
      const float nx = m0 * x[i] + m1 * y[i] + m2 * z[i];
      const float ny = m3 * x[i] + m4 * y[i] + m5 * z[i];
      const float nz = m6 * x[i] + m7 * y[i] + m8 * z[i];
      // Behind the visible hemisphere: the nearest rim point ((0, -1) straight behind).
      const float l2 = nx * nx + ny * ny;
      const bool behind = nz < 0.0f;
      const bool straight = !(l2 > 0.0f);
      const float inv = 1.0f / std::sqrt(straight ? 1.0f : l2);
      const float s = behind ? inv : 1.0f;
      const bool fixed = behind & straight;
      disc_x[i] = fixed ? 0.0f : nx * s;
      disc_y[i] = fixed ? -1.0f : ny * s;
      rim[i] = nz;
    }
  }
}

namespace {
void to_floats(const Mat3& M, float m[9]) {
  for (int i = 0; i < 9; ++i) m[i] = float(M(i / 3, i % 3));
}
constexpr int kBlock = 64;  // texels per stack block of the single-precision forms
}  // namespace

void Warp::warp_block(CentralDirection kind, const Mat3& source_from_dest, int width, int height, int row, int c_begin,
                      int c_end, float* disc_x, float* disc_y, float* rim) const {
  WarpSample samples[kBlock];
  for (int c = c_begin; c < c_end; c += kBlock) {
    const int e = std::min(c + kBlock, c_end);
    warp_row(kind, source_from_dest, width, height, row, c, e, samples);
    for (int i = 0; i < e - c; ++i) {
      disc_x[c - c_begin + i] = float(samples[i].disc.x());
      disc_y[c - c_begin + i] = float(samples[i].disc.y());
      rim[c - c_begin + i] = float(samples[i].rim);
    }
  }
}

bool Warp::central_block(CentralDirection, int, int, int, int, int, float*, float*, float*) const { return false; }

void ExactWarp::warp_block(CentralDirection kind, const Mat3& source_from_dest, int width, int height, int row,
                           int c_begin, int c_end, float* disc_x, float* disc_y, float* rim) const {
  float m[9];
  to_floats(source_from_dest, m);
  float x[kBlock], y[kBlock], z[kBlock];
  for (int c = c_begin; c < c_end; c += kBlock) {
    const int e = std::min(c + kBlock, c_end), o = c - c_begin;
    central_directions_row(kind, width, height, row, c, e, x, y, z);
    warp_directions(kind, m, e - c, x, y, z, disc_x + o, disc_y + o, rim + o);
  }
}

bool ExactWarp::central_block(CentralDirection kind, int width, int height, int row, int c_begin, int c_end, float* x,
                              float* y, float* z) const {
  central_directions_row(kind, width, height, row, c_begin, c_end, x, y, z);
  return true;
}

void ExactWarp::warp_row(CentralDirection kind, const Mat3& source_from_dest, int width, int height, int row,
                         int c_begin, int c_end, WarpSample* out) const {
  for (int c = c_begin; c < c_end; ++c) {
    const Vec2 xy = sphere_map::disc_from_pixel(Vec2(c, row), width, height);
    out[c - c_begin] = warp_direction(kind, source_from_dest * central_direction(kind, xy));
  }
}

PrecomputedWarp::PrecomputedWarp(int width, int height) : width_(width), height_(height) {
  if (width < 1 || height < 1) throw std::invalid_argument("PrecomputedWarp: size must be positive");
  const std::size_t count = std::size_t(width) * std::size_t(height);
  mirror_.resize(count);
  normal_.resize(count);
  planes_.assign(6 * count, 0.0f);
  for (int r = 0; r < height; ++r) {
    for (int c = 0; c < width; ++c) {
      const Vec2 xy = sphere_map::disc_from_pixel(Vec2(c, r), width, height);
      const std::size_t i = std::size_t(r) * std::size_t(width) + std::size_t(c);
      mirror_[i] = sphere_map::g_mirror(xy);
      normal_[i] = sphere_map::g_normal(xy);
    }
    const auto [c0, c1] = disc_span(r, width, height);
    const std::size_t at = std::size_t(r) * std::size_t(width) + std::size_t(c0);
    for (int k = 0; k < 2; ++k)
      central_directions_row(CentralDirection(k), width, height, r, c0, c1, planes_.data() + (3 * k) * count + at,
                             planes_.data() + (3 * k + 1) * count + at, planes_.data() + (3 * k + 2) * count + at);
  }
}

void PrecomputedWarp::check_size(int width, int height) const {
  if (width != width_ || height != height_)
    throw std::invalid_argument("PrecomputedWarp: built for " + std::to_string(width_) + "x" + std::to_string(height_) +
                                ", asked for " + std::to_string(width) + "x" + std::to_string(height));
}

void PrecomputedWarp::warp_row(CentralDirection kind, const Mat3& source_from_dest, int width, int height, int row,
                               int c_begin, int c_end, WarpSample* out) const {
  check_size(width, height);
  const Vec3* table =
      (kind == CentralDirection::Mirror ? mirror_.data() : normal_.data()) + std::size_t(row) * std::size_t(width);
  if (kind == CentralDirection::Mirror) {
    for (int c = c_begin; c < c_end; ++c) out[c - c_begin] = mirror_inverse(source_from_dest * table[c]);
  } else {
    for (int c = c_begin; c < c_end; ++c) out[c - c_begin] = normal_inverse(source_from_dest * table[c]);
  }
}

void PrecomputedWarp::warp_block(CentralDirection kind, const Mat3& source_from_dest, int width, int height, int row,
                                 int c_begin, int c_end, float* disc_x, float* disc_y, float* rim) const {
  check_size(width, height);
  float m[9];
  to_floats(source_from_dest, m);
  const std::size_t count = std::size_t(width) * std::size_t(height);
  const float* p = planes_.data() + std::size_t(3 * int(kind)) * count + std::size_t(row) * std::size_t(width) +
                   std::size_t(c_begin);
  warp_directions(kind, m, c_end - c_begin, p, p + count, p + 2 * count, disc_x, disc_y, rim);
}

bool PrecomputedWarp::central_block(CentralDirection kind, int width, int height, int row, int c_begin, int c_end,
                                    float* x, float* y, float* z) const {
  check_size(width, height);
  const std::size_t count = std::size_t(width) * std::size_t(height);
  const float* p = planes_.data() + std::size_t(3 * int(kind)) * count + std::size_t(row) * std::size_t(width) +
                   std::size_t(c_begin);
  const std::size_t n = std::size_t(c_end - c_begin);
  std::copy(p, p + n, x);
  std::copy(p + count, p + count + n, y);
  std::copy(p + 2 * count, p + 2 * count + n, z);
  return true;
}

}  // namespace rsibr
