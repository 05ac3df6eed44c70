#include "core/env_map.h"

#include "core/parallel.h"
#include "core/sphere_map.h"

#include <algorithm>
#include <cmath>

namespace rsibr {

EnvMap EnvMap::zeros(const Layout& layout, int channels) {
  EnvMap m;
  m.layout = layout;
  m.pixels = cv::Mat::zeros(layout.height(), layout.width(), CV_32FC(channels));
  return m;
}

namespace {

struct Tap {
  int c, r;
  float w;
};

inline void accumulate(const cv::Mat& img, const Tap* taps, int n, float* out) {
  const int ch = img.channels();
  for (int k = 0; k < ch; ++k) out[k] = 0.f;
  for (int i = 0; i < n; ++i) {
    if (taps[i].w == 0.f) continue;
    const float* px = img.ptr<float>(taps[i].r) + std::size_t(taps[i].c) * ch;
    for (int k = 0; k < ch; ++k) out[k] += taps[i].w * px[k];
  }
}

// Four bilinear taps around p with indices clamped to [x0,x1] x [y0,y1].
inline void clamped_taps(const Vec2& p, int x0, int x1, int y0, int y1, Tap* t) {
  const double x = std::clamp(p.x(), double(x0), double(x1));
  const double y = std::clamp(p.y(), double(y0), double(y1));
  int c0 = std::min(int(std::floor(x)), x1 - 1 >= x0 ? x1 - 1 : x0);
  int r0 = std::min(int(std::floor(y)), y1 - 1 >= y0 ? y1 - 1 : y0);
  c0 = std::max(c0, x0);
  r0 = std::max(r0, y0);
  const int c1 = std::min(c0 + 1, x1), r1 = std::min(r0 + 1, y1);
  const float fx = float(x - c0), fy = float(y - r0);
  t[0] = {c0, r0, (1 - fx) * (1 - fy)};
  t[1] = {c1, r0, fx * (1 - fy)};
  t[2] = {c0, r1, (1 - fx) * fy};
  t[3] = {c1, r1, fx * fy};
}

}  // namespace

void sample_bilinear(const EnvMap& map, const Vec3& dir, float* out) {
  const Layout& L = map.layout;
  const int W = L.width(), H = L.height();
  Tap taps[4];
  switch (L.kind()) {
    case LayoutKind::LatLong: clamped_taps(L.pixel(dir), 0, W - 1, 0, H - 1, taps); break;
    case LayoutKind::Cube: {
      // Stay inside the face the direction belongs to (its edge texels lie on the cube's edges).
      const Vec2 p = L.pixel(dir);
      const int face = std::clamp(int(std::floor((p.y() + 0.5) / W)), 0, 5);
      clamped_taps(p, 0, W - 1, face * W, face * W + W - 1, taps);
      break;
    }
    case LayoutKind::Octahedral: {
      const Vec2 p = L.pixel(dir);
      const int c0 = int(std::floor(p.x())), r0 = int(std::floor(p.y()));
      const float fx = float(p.x() - c0), fy = float(p.y() - r0);
      const int N = W;
      // Neighbours across the square's border: the octahedral fold makes (u, 1) and (-u, 1) (and
      // likewise on every edge) the same direction, so texel (c, -1) is texel (N-1-c, 0).
      auto wrap = [N](int c, int r) {
        if (c < 0) {
          c = 0;
          r = N - 1 - r;
        } else if (c >= N) {
          c = N - 1;
          r = N - 1 - r;
        }
        if (r < 0) {
          r = 0;
          c = N - 1 - c;
        } else if (r >= N) {
          r = N - 1;
          c = N - 1 - c;
        }
        return std::pair<int, int>(std::clamp(c, 0, N - 1), std::clamp(r, 0, N - 1));
      };
      const int cs[4] = {c0, c0 + 1, c0, c0 + 1}, rs[4] = {r0, r0, r0 + 1, r0 + 1};
      const float ws[4] = {(1 - fx) * (1 - fy), fx * (1 - fy), (1 - fx) * fy, fx * fy};
      for (int i = 0; i < 4; ++i) {
        const auto [c, r] = wrap(cs[i], rs[i]);
        taps[i] = {c, r, ws[i]};
      }
      break;
    }
    case LayoutKind::Sphere: {
      Vec2 xy = sphere_map::g_mirror_inv(dir);
      if (xy.norm() > 1.0 - 2.0 / std::min(W, H)) {
        sample_nearest(map, dir, out);
        return;
      }
      for (int attempt = 0;; ++attempt) {
        const Vec2 p = sphere_map::pixel_from_disc(xy, W, H);
        clamped_taps(p, 0, W - 1, 0, H - 1, taps);
        float total = 0.f;
        for (Tap& t : taps) {
          const Vec2 q = sphere_map::disc_from_pixel(Vec2(t.c, t.r), W, H);
          if (q.squaredNorm() > 1.0) t.w = 0.f;
          total += t.w;
        }
        if (total > 0.f) {
          for (Tap& t : taps) t.w /= total;
          break;
        }
        if (attempt == 8) {  // cannot happen for W, H >= 2; keep a defined answer anyway
          for (Tap& t : taps) t.w = 0.f;
          break;
        }
        // Every tap lies outside the disc (a point on the rim of a small map): step inward.
        xy *= 1.0 - 1.0 / std::max(W, H);
      }
      break;
    }
  }
  accumulate(map.pixels, taps, 4, out);
}

void sample_nearest(const EnvMap& map, const Vec3& dir, float* out) {
  const Layout& L = map.layout;
  const int W = L.width(), H = L.height();
  Vec2 p = L.pixel(dir);
  int c = int(std::floor(p.x() + 0.5)), r = int(std::floor(p.y() + 0.5));
  c = std::clamp(c, 0, W - 1);
  if (L.kind() == LayoutKind::Cube) {
    const int face = std::clamp(int(std::floor((p.y() + 0.5) / W)), 0, 5);
    r = std::clamp(r, face * W, face * W + W - 1);
  } else {
    r = std::clamp(r, 0, H - 1);
  }
  const Tap tap{c, r, 1.f};
  accumulate(map.pixels, &tap, 1, out);
}

namespace {
// Row r's texel solid angles into w (width entries): a lat-long row's are equal but for its two
// seam columns, so two sines per row serve it.
void row_solid_angles(const Layout& layout, int r, double* w) {
  const int width = layout.width();
  if (layout.kind() == LayoutKind::LatLong) {
    const double seam = layout.texel_solid_angle(0, r), inner = layout.texel_solid_angle(width > 2 ? 1 : 0, r);
    for (int c = 0; c < width; ++c) w[c] = c == 0 || c == width - 1 ? seam : inner;
    return;
  }
  for (int c = 0; c < width; ++c) w[c] = layout.texel_solid_angle(c, r);
}
}  // namespace

cv::Mat texel_solid_angles(const Layout& layout) {
  cv::Mat sa(layout.height(), layout.width(), CV_64FC1);
  parallel_for_rows(layout.height(), [&](int r) { row_solid_angles(layout, r, sa.ptr<double>(r)); });
  return sa;
}

std::vector<double> integral(const EnvMap& map) {
  const int ch = map.channels(), rows = map.pixels.rows, cols = map.pixels.cols;
  // Each row's sums in parallel, then the rows added in order: the same result on any threads.
  std::vector<double> row_sums(std::size_t(rows) * std::size_t(ch), 0.0);
  parallel_for_rows(rows, [&](int r) {
    std::vector<double> w(static_cast<std::size_t>(cols));
    row_solid_angles(map.layout, r, w.data());
    const float* px = map.pixels.ptr<float>(r);
    double* sum = &row_sums[std::size_t(r) * std::size_t(ch)];
    for (int c = 0; c < cols; ++c)
      for (int k = 0; k < ch; ++k) sum[k] += double(px[c * ch + k]) * w[std::size_t(c)];
  });
  std::vector<double> total(ch, 0.0);
  for (int r = 0; r < rows; ++r)
    for (int k = 0; k < ch; ++k) total[std::size_t(k)] += row_sums[std::size_t(r) * std::size_t(ch) + std::size_t(k)];
  return total;
}

}  // namespace rsibr
