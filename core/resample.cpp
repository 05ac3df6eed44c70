#include "core/resample.h"

#include "core/latlong_ripmap.h"
#include "core/parallel.h"
#include "core/sphere_map.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <map>
#include <optional>
#include <vector>

#if defined(__SSE2__)
#include <xmmintrin.h>
#endif

namespace rsibr {

PixelFootprint pixel_footprint(const Layout& layout, const Vec2& p) {
  // Closed forms where the Jacobian is simple; central differences otherwise.
  switch (layout.kind()) {
    case LayoutKind::LatLong: {
      // Latitude step pi/(H-1); longitude step 2 pi/(W-1), shortened by cos(latitude).
      const double dlat = kPi / (layout.height() - 1), dlon = 2 * kPi / (layout.width() - 1);
      const double across = std::abs(std::cos(0.5 * kPi - dlat * p.y())) * dlon;
      return {std::min(dlat, across), std::max(dlat, across)};
    }
    case LayoutKind::Sphere: {
      // Mirror ball, rho = |(x,y)|: radially d(theta)/d(rho) = 2/sqrt(1-rho^2), tangentially
      // 2 sqrt(1-rho^2); one pixel is 2/W (2/H) in disc units.
      const Vec2 xy = sphere_map::disc_from_pixel(p, layout.width(), layout.height());
      const double z = std::sqrt(std::max(1e-12, 1.0 - xy.squaredNorm()));
      if (xy.squaredNorm() > 1.0) return {};
      const double fine = 2.0 / std::max(layout.width(), layout.height());
      const double coarse = 2.0 / std::min(layout.width(), layout.height());
      return {2 * z * fine, 2 / z * coarse};
    }
    default: break;
  }
  const double h = 0.25;
  const std::optional<Vec3> d0 = layout.direction(p);
  if (!d0) return {};
  // Derivative along one axis, central where both sides exist, else one-sided.
  auto derivative = [&](const Vec2& axis) -> Vec3 {
    const auto a = layout.direction(p + h * axis), b = layout.direction(p - h * axis);
    if (a && b) return (*a - *b) / (2 * h);
    if (a) return (*a - *d0) / h;
    if (b) return (*d0 - *b) / h;
    return Vec3::Zero();
  };
  const Vec3 jx = derivative(Vec2(1, 0)), jy = derivative(Vec2(0, 1));
  // Singular values of the 3x2 Jacobian [jx jy] from its 2x2 Gram matrix.
  const double a = jx.squaredNorm(), b = jx.dot(jy), c = jy.squaredNorm();
  const double mean = 0.5 * (a + c), dev = std::sqrt(std::max(0.0, 0.25 * (a - c) * (a - c) + b * b));
  return {std::sqrt(std::max(0.0, mean - dev)), std::sqrt(mean + dev)};
}

namespace {

// A destination point with its unit direction, its level-0 source position and the destination's
// solid-angle density there; ok is false where the point has no direction or no area.
struct PointSample {
  bool ok = false;
  Vec3 dir = Vec3::Zero();
  double x = 0, y = 0, density = 0;
};

PointSample point_sample(const Layout& dst, const Layout& src, const Vec2& p) {
  PointSample s;
  const std::optional<Vec3> d = dst.direction(p);
  if (!d) return s;
  s.density = dst.solid_angle_density(p);
  if (!(s.density > 0) || !std::isfinite(s.density)) return s;
  s.dir = d->normalized();
  const Vec2 q = src.pixel(s.dir);
  s.x = q.x(), s.y = q.y();
  s.ok = std::isfinite(s.x) && std::isfinite(s.y);
  return s;
}

// Upper bounds of a lat-long map's magnitude over squares of source texels: level l holds the
// maxima over 2^l x 2^l blocks, dilated by one block, so the value read at a position bounds every
// texel within 2^l of it.
class PeakPyramid {
 public:
  PeakPyramid(const cv::Mat& magnitude, double energy, double tolerance) : energy_(energy), tolerance_(tolerance) {
    if (!(energy > 0) || magnitude.empty()) return;
    cv::Mat level = magnitude;
    for (;;) {
      cv::Mat dilated;
      cv::dilate(level, dilated, cv::Mat::ones(3, 3, CV_8U));
      levels_.push_back(dilated);
      if (level.rows <= 2 && level.cols <= 2) break;
      cv::Mat next((level.rows + 1) / 2, (level.cols + 1) / 2, CV_32F);
      for (int r = 0; r < next.rows; ++r)
        for (int c = 0; c < next.cols; ++c) {
          float m = 0;
          for (int dr = 0; dr < 2; ++dr)
            for (int dc = 0; dc < 2; ++dc)
              m = std::max(m,
                           level.at<float>(std::min(2 * r + dr, level.rows - 1), std::min(2 * c + dc, level.cols - 1)));
          next.at<float>(r, c) = m;
        }
      level = next;
    }
  }
  // Whether a texel of this solid-angle density (per destination texel area) whose source
  // footprint spans `spread` texels around (x, y) could hold more than the tolerance of the energy.
  bool bright(double x, double y, double spread, double density) const {
    if (levels_.empty()) return false;
    int l = 0;
    while (l + 1 < int(levels_.size()) && double(1L << l) < spread) ++l;
    const cv::Mat& m = levels_[std::size_t(l)];
    const double scale = 1.0 / double(1L << l);
    const int c = std::clamp(int(std::lround(x * scale)), 0, m.cols - 1);
    const int r = std::clamp(int(std::lround(y * scale)), 0, m.rows - 1);
    return double(m.at<float>(r, c)) * density > tolerance_ * energy_;
  }

 private:
  std::vector<cv::Mat> levels_;
  double energy_ = 0, tolerance_ = 0;
};

// The n x n taps of one texel from ripmap level `level`, for RGB: corner positions x, y (level-0
// pixels, unwrapped) and densities w in the order top-left, top-right, bottom-left, bottom-right,
// the corner lines at pixel offsets y_top and y_bottom. The same taps as LatLongRipmap::bilinear,
// with the level's constants hoisted out of the loop: along a row of taps the position and density
// step by constants, and a row's n taps (n <= 64) are summed in float, the rows then in double. A cell whose corners lie inside the level (neither seam nor pole within
// it) needs no wrapping or clamping per tap; the taps are convex combinations of the corners.
void rgb_taps(const LatLongRipmap& ripmap, int level, int n, const double* x, const double* y, const double* w,
              double y_top, double y_bottom, float* px) {
  const cv::Mat& m = ripmap.level(level);
  const int cols = m.cols, rows = m.rows;
  const double period = cols - 1, to_level = ripmap.inverse_scale(level), last_row = rows - 1;
  const std::size_t stride = m.step1();
  const float* base = m.ptr<float>(0);
  const double x_lo = std::min({x[0], x[1], x[2], x[3]}) * to_level,
               x_hi = std::max({x[0], x[1], x[2], x[3]}) * to_level;
  const double y_lo = std::min({y[0], y[1], y[2], y[3]}), y_hi = std::max({y[0], y[1], y[2], y[3]});
  const bool inside = x_lo >= 0 && x_hi <= period && y_lo >= 0 && y_hi <= last_row;
  const double inv_n = 1.0 / n;
  double r = 0, g = 0, b = 0, wsum = 0;
  for (int j = 0; j < n; ++j) {
    const double t = ((j + 0.5) * inv_n - 0.5 - y_top) / (y_bottom - y_top);
    const double lx = (x[0] + t * (x[2] - x[0])) * to_level, rx = (x[1] + t * (x[3] - x[1])) * to_level;
    const double ly = y[0] + t * (y[2] - y[0]), ry = y[1] + t * (y[3] - y[1]);
    const double lw = w[0] + t * (w[2] - w[0]), rw = w[1] + t * (w[3] - w[1]);
    const double dx = (rx - lx) * inv_n, dy = (ry - ly) * inv_n, dw = (rw - lw) * inv_n;
    double xx = lx + 0.5 * dx, yy = ly + 0.5 * dy, tw = lw + 0.5 * dw;
    float fr = 0, fg = 0, fb = 0, fw = 0;
#if defined(__SSE2__)
    __m128 sum = _mm_setzero_ps();
#endif
    for (int i = 0; i < n; ++i, xx += dx, yy += dy, tw += dw) {
      double u = xx, v = yy;
      if (!inside) {
        if (u < 0 || u > period) u -= period * std::floor(u / period);
        u = std::clamp(u, 0.0, period);
        v = std::clamp(v, 0.0, last_row);
      }
      const int c0 = std::min(int(u), cols - 2), r0 = std::min(int(v), rows - 2);
      const float fx = float(u - c0), fy = float(v - r0), wt = float(tw);
      const float* a = base + std::size_t(r0) * stride + std::size_t(c0) * 3;
      const float* d = a + stride;
#if defined(__SSE2__)
      // RGB in three lanes: texel c0 from a[0..3], texel c0 + 1 from a[2..5] moved down one lane
      // (a[6] may lie past the map's last texel, so it is never read).
      const __m128 left_top = _mm_loadu_ps(a), left_bottom = _mm_loadu_ps(d);
      const __m128 right_top = _mm_shuffle_ps(_mm_loadu_ps(a + 2), _mm_loadu_ps(a + 2), _MM_SHUFFLE(3, 3, 2, 1));
      const __m128 right_bottom = _mm_shuffle_ps(_mm_loadu_ps(d + 2), _mm_loadu_ps(d + 2), _MM_SHUFFLE(3, 3, 2, 1));
      const __m128 vx = _mm_set1_ps(fx), vy = _mm_set1_ps(fy);
      const __m128 top = _mm_add_ps(left_top, _mm_mul_ps(vx, _mm_sub_ps(right_top, left_top)));
      const __m128 bottom = _mm_add_ps(left_bottom, _mm_mul_ps(vx, _mm_sub_ps(right_bottom, left_bottom)));
      sum = _mm_add_ps(sum, _mm_mul_ps(_mm_set1_ps(wt), _mm_add_ps(top, _mm_mul_ps(vy, _mm_sub_ps(bottom, top)))));
#else
      const float t0 = a[0] + fx * (a[3] - a[0]), t1 = a[1] + fx * (a[4] - a[1]), t2 = a[2] + fx * (a[5] - a[2]);
      const float b0 = d[0] + fx * (d[3] - d[0]), b1 = d[1] + fx * (d[4] - d[1]), b2 = d[2] + fx * (d[5] - d[2]);
      fr += wt * (t0 + fy * (b0 - t0));
      fg += wt * (t1 + fy * (b1 - t1));
      fb += wt * (t2 + fy * (b2 - t2));
#endif
      fw += wt;
    }
#if defined(__SSE2__)
    alignas(16) float lanes[4];
    _mm_store_ps(lanes, sum);
    fr = lanes[0], fg = lanes[1], fb = lanes[2];
#endif
    r += fr, g += fg, b += fb, wsum += fw;
  }
  px[0] = float(r / wsum), px[1] = float(g / wsum), px[2] = float(b / wsum);
}

// The destination's corner points x = c - 1/2 (c = 0..W) on the boundary line y = b - 1/2 between
// rows b - 1 and b, as row q (b - 1 or b) sees it: a cube's faces are stacked, so on a face
// boundary the line is taken a hair inside row q's face. Lines are computed once per range of
// rows and shared by the rows on either side.
class CornerLines {
 public:
  static constexpr double kInset = 1e-3;

  CornerLines(const Layout& dst, const Layout& src) : dst_(dst), src_(src) {}

  bool face_boundary(int b) const { return dst_.kind() == LayoutKind::Cube && b % dst_.width() == 0; }
  // Rows q and q2 lie on one smooth piece of the destination (a cube: the same face).
  bool same_piece(int q, int q2) const {
    return q2 >= 0 && q2 < dst_.height() && (dst_.kind() != LayoutKind::Cube || q / dst_.width() == q2 / dst_.width());
  }
  // y of line b as row q sees it, relative to b - 1/2.
  double offset(int b, int q) const { return face_boundary(b) ? (q == b ? kInset : -kInset) : 0.0; }

  const std::vector<PointSample>& line(int b, int q) {
    const std::pair<int, int> key(b, face_boundary(b) ? q - b : 0);
    auto it = cache_.find(key);
    if (it != cache_.end()) return it->second;
    std::vector<PointSample> points(std::size_t(dst_.width()) + 1);
    const double y = b - 0.5 + offset(b, q);
    for (int c = 0; c <= dst_.width(); ++c) points[std::size_t(c)] = point_sample(dst_, src_, Vec2(c - 0.5, y));
    return cache_.emplace(key, std::move(points)).first->second;
  }
  void forget_above(int b) {
    while (!cache_.empty() && cache_.begin()->first.first < b) cache_.erase(cache_.begin());
  }

 private:
  const Layout& dst_;
  const Layout& src_;
  std::map<std::pair<int, int>, std::vector<PointSample>> cache_;
};

// Destination rows [r0, r1) by interpolated taps from a lat-long source (see resample()).
// A texel's bilinear interpolation of the source position (and density) between its corners is
// trusted where the second differences of the corner lines bound its error, (|f_xx| + |f_yy|) / 8,
// within a fiftieth of a texel of the level read (a thousandth of the density); elsewhere (a pole,
// a seam's far side, a sphere map's rim) exact(c, r, px) renders the texel.
template <class Exact>
void interpolated_rows(const EnvMap& src, const Layout& dst, const LatLongRipmap& ripmap,
                       const ResampleOptions& options, const PeakPyramid& peaks, int r0, int r1, EnvMap& out,
                       const Exact& exact) {
  constexpr double kPositionTolerance = 0.02, kDensityTolerance = 1e-3;
  const int width = dst.width(), ch = src.channels(), max_n = std::max(1, options.max_subsamples);
  const double period = src.layout.width() - 1, dlat = ripmap.latitude_step();
  CornerLines lines(dst, src.layout);
  double acc[kMaxChannels];
  float tap[kMaxChannels];
  for (int r = r0; r < r1; ++r) {
    lines.forget_above(r - 1);
    const std::vector<PointSample>& top = lines.line(r, r);
    const std::vector<PointSample>& bottom = lines.line(r + 1, r);
    // A third line on the same piece, for the second difference across rows.
    const std::vector<PointSample>* third = nullptr;
    bool third_below = true;
    if (lines.same_piece(r, r + 1)) {
      third = &lines.line(r + 2, r + 1);
    } else if (lines.same_piece(r, r - 1)) {
      third = &lines.line(r - 1, r - 1);
      third_below = false;
    }
    float* row = out.pixels.ptr<float>(r);
    for (int c = 0; c < width; ++c) {
      float* px = row + std::size_t(c) * ch;
      const PointSample* k[4] = {&top[std::size_t(c)], &top[std::size_t(c) + 1], &bottom[std::size_t(c)],
                                 &bottom[std::size_t(c) + 1]};
      bool ok = third != nullptr && k[0]->ok && k[1]->ok && k[2]->ok && k[3]->ok;
      const double ref = ok ? k[0]->x : 0.0;
      const auto unwrap = [&](double x) { return x - period * std::round((x - ref) / period); };
      double x[4], y[4], w[4];
      for (int i = 0; ok && i < 4; ++i) x[i] = unwrap(k[i]->x), y[i] = k[i]->y, w[i] = k[i]->density;
      // Second differences along each line (at the texel's corners that have both neighbours) and
      // across the rows (at its two columns).
      double fxx[3] = {0, 0, 0}, fyy[3] = {0, 0, 0};  // x, y, density
      for (int side = 0; ok && side < 2; ++side) {
        const std::vector<PointSample>& l = side == 0 ? top : bottom;
        for (int m = c; m <= c + 1; ++m) {
          if (m - 1 < 0 || m + 1 > width) continue;
          const PointSample &a = l[std::size_t(m) - 1], &b = l[std::size_t(m)], &d = l[std::size_t(m) + 1];
          if (!a.ok || !b.ok || !d.ok) {
            ok = false;
            break;
          }
          fxx[0] = std::max(fxx[0], std::abs(unwrap(a.x) - 2 * unwrap(b.x) + unwrap(d.x)));
          fxx[1] = std::max(fxx[1], std::abs(a.y - 2 * b.y + d.y));
          fxx[2] = std::max(fxx[2], std::abs(a.density - 2 * b.density + d.density));
        }
      }
      for (int m = c; ok && m <= c + 1; ++m) {
        const PointSample& t = (*third)[std::size_t(m)];
        if (!t.ok) {
          ok = false;
          break;
        }
        const PointSample &u = top[std::size_t(m)], &v = bottom[std::size_t(m)];
        const PointSample &a = third_below ? u : t, &b = third_below ? v : u, &d = third_below ? t : v;
        fyy[0] = std::max(fyy[0], std::abs(unwrap(a.x) - 2 * unwrap(b.x) + unwrap(d.x)));
        fyy[1] = std::max(fyy[1], std::abs(a.y - 2 * b.y + d.y));
        fyy[2] = std::max(fyy[2], std::abs(a.density - 2 * b.density + d.density));
      }
      if (!ok) {
        exact(c, r, px);
        continue;
      }
      const double mid_x = 0.25 * (x[0] + x[1] + x[2] + x[3]), mid_y = 0.25 * (y[0] + y[1] + y[2] + y[3]);
      const double mid_w = 0.25 * (w[0] + w[1] + w[2] + w[3]);
      const double lat = 0.5 * kPi - dlat * mid_y;
      const int level = ripmap.level_for_latitude(lat);
      const double level_columns = (ripmap.width(level) - 1) / period;  // level texels per level-0 texel
      if ((fxx[0] + fyy[0]) / 8 * level_columns > kPositionTolerance || (fxx[1] + fyy[1]) / 8 > kPositionTolerance ||
          (fxx[2] + fyy[2]) / 8 > kDensityTolerance * mid_w || !(mid_w > 0)) {
        exact(c, r, px);
        continue;
      }
      // A texel that may hold more than the energy tolerance of the whole map (a sun and its
      // neighbours: the brightest source texel anywhere in its footprint times its solid angle)
      // takes the exact path: the interpolated cell's small bulge against the true one would move a
      // real share of the map's energy.
      const double spread =
          std::max({std::abs(x[0] - x[3]), std::abs(x[1] - x[2]), std::abs(y[0] - y[3]), std::abs(y[1] - y[2])});
      if (peaks.bright(mid_x, mid_y, spread, mid_w)) {
        exact(c, r, px);
        continue;
      }
      // The cell's largest angular extent: its edges and half diagonals (chords, radians).
      const double vertical = 1.0 / (1.0 - lines.offset(r, r) + lines.offset(r + 1, r));
      const double extent =
          std::max({(k[0]->dir - k[1]->dir).norm(), (k[2]->dir - k[3]->dir).norm(),
                    vertical * (k[0]->dir - k[2]->dir).norm(), vertical * (k[1]->dir - k[3]->dir).norm(),
                    std::sqrt(0.5) * (k[0]->dir - k[3]->dir).norm(), std::sqrt(0.5) * (k[1]->dir - k[2]->dir).norm()});
      const double step = std::min(dlat, ripmap.longitude_step(level) * std::abs(std::cos(lat)));
      const double footprint = step > 0 ? extent / step : double(max_n);
      const int n = std::clamp(int(std::ceil(options.supersampling * footprint - 1e-9)), 1, max_n);
      if (n == 1) {  // enlarging: one bilinear tap at the exact centre, as sample_bilinear takes it
        const PointSample centre = point_sample(dst, src.layout, Vec2(c, r));
        if (centre.ok)
          ripmap.bilinear(level, centre.x, centre.y, px);
        else
          exact(c, r, px);
        continue;
      }
      // Tap (i, j) at pixel offset ((i + 1/2) / n - 1/2, (j + 1/2) / n - 1/2) from the centre; the
      // corners' lines lie at offsets -1/2 + top and 1/2 + bottom (the insets).
      const double y_top = -0.5 + lines.offset(r, r), y_bottom = 0.5 + lines.offset(r + 1, r);
      if (ch == 3) {
        rgb_taps(ripmap, level, n, x, y, w, y_top, y_bottom, px);
        continue;
      }
      for (int q = 0; q < ch; ++q) acc[q] = 0.0;
      double wsum = 0.0;
      for (int j = 0; j < n; ++j) {
        const double t = ((j + 0.5) / n - 0.5 - y_top) / (y_bottom - y_top);
        const double lx = x[0] + t * (x[2] - x[0]), rx = x[1] + t * (x[3] - x[1]);
        const double ly = y[0] + t * (y[2] - y[0]), ry = y[1] + t * (y[3] - y[1]);
        const double lw = w[0] + t * (w[2] - w[0]), rw = w[1] + t * (w[3] - w[1]);
        for (int i = 0; i < n; ++i) {
          const double s = (i + 0.5) / n;
          const double tw = lw + s * (rw - lw);
          ripmap.bilinear(level, lx + s * (rx - lx), ly + s * (ry - ly), tap);
          for (int q = 0; q < ch; ++q) acc[q] += tw * tap[q];
          wsum += tw;
        }
      }
      for (int q = 0; q < ch; ++q) px[q] = float(acc[q] / wsum);
    }
  }
}

}  // namespace

EnvMap resample(const EnvMap& src, const Layout& dst, const ResampleOptions& options) {
  EnvMap out = EnvMap::zeros(dst, src.channels());
  out.attributes = src.attributes;
  const int ch = src.channels();
  const int max_n = std::max(1, options.max_subsamples);
  std::atomic<int> rows_done{0};
  const auto lookup = options.reconstruction == Reconstruction::Nearest ? &sample_nearest : &sample_bilinear;

  // Local peak magnitude of the source (max over channels and the 3x3 neighbourhood) and the
  // energy of |L|, for the energy-driven tap count.
  EnvMap peak;
  double energy = 0;
  cv::Mat magnitude;
  const bool interpolated = src.layout.kind() == LayoutKind::LatLong &&
                            options.reconstruction == Reconstruction::Bilinear && options.interpolate_taps;
  if (options.energy_tolerance > 0 || interpolated) {
    peak.layout = src.layout;
    magnitude.create(src.pixels.rows, src.pixels.cols, CV_32FC1);
    parallel_for_rows(src.pixels.rows, [&](int r) {
      const float* p = src.pixels.ptr<float>(r);
      float* m = magnitude.ptr<float>(r);
      for (int c = 0; c < src.pixels.cols; ++c) {
        float v = 0;
        for (int k = 0; k < ch; ++k) v = std::max(v, std::isfinite(p[c * ch + k]) ? std::abs(p[c * ch + k]) : 0.f);
        m[c] = v;
      }
    });
    cv::dilate(magnitude, peak.pixels, cv::Mat::ones(3, 3, CV_8U));
    energy = integral(EnvMap{src.layout, magnitude, {}})[0];
  }
  // Taps per side a texel of this solid-angle density needs so that no tap carries more than the
  // energy tolerance of the whole map's energy (1 where the tolerance is off).
  const auto energy_taps = [&](const Vec3& dir, double density) {
    if (!(energy > 0) || !(options.energy_tolerance > 0)) return 1;
    float local_peak = 0;
    sample_nearest(peak, dir, &local_peak);
    const double need = std::sqrt(local_peak * density / (options.energy_tolerance * energy));
    return std::clamp(int(std::ceil(need)), 1, max_n);
  };

  // The exact path: every tap's direction and source position computed.
  const auto exact_texel = [&](int c, int r, float* px) {
    float tap[kMaxChannels];
    double acc[kMaxChannels];
    const Vec2 centre(c, r);
    std::optional<Vec3> dir = dst.direction(centre);
    bool partial_rim = false;
    if (dst.kind() == LayoutKind::Sphere) {
      // Only texels within a texel diagonal of the rim can straddle it.
      const Vec2 xy = sphere_map::disc_from_pixel(centre, dst.width(), dst.height());
      const double margin = 2.0 * std::sqrt(2.0) / std::min(dst.width(), dst.height());
      if (std::abs(xy.norm() - 1.0) < margin) {
        const double omega = dst.texel_solid_angle(c, r);
        partial_rim = omega > 0 && omega < 0.999 * 16.0 / (double(dst.width()) * dst.height());
      }
    }
    if (!dir && !partial_rim) return;  // outside the sphere map's disc: no direction, stays 0

    int n = 1;
    if (dir) {
      const double extent = pixel_footprint(dst, centre).max_radians;
      const double src_step = pixel_footprint(src.layout, src.layout.pixel(*dir)).min_radians;
      const double k = src_step > 0 ? extent / src_step : double(max_n);
      n = std::clamp(int(std::ceil(options.supersampling * k - 1e-9)), 1, max_n);
    }
    if (partial_rim) n = std::max(n, 8);  // resolve the disc's edge inside the texel
    if (dir) n = std::max(n, energy_taps(*dir, dst.solid_angle_density(centre)));

    if (n == 1) {
      lookup(src, *dir, px);
      return;
    }
    for (int k = 0; k < ch; ++k) acc[k] = 0.0;
    double wsum = 0.0;
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const Vec2 q = centre + Vec2((i + 0.5) / n - 0.5, (j + 0.5) / n - 0.5);
        const double w = dst.solid_angle_density(q);
        if (!(w > 0)) continue;
        const std::optional<Vec3> d = dst.direction(q);
        if (!d) continue;
        lookup(src, *d, tap);
        for (int k = 0; k < ch; ++k) acc[k] += w * tap[k];
        wsum += w;
      }
    if (wsum > 0) {
      for (int k = 0; k < ch; ++k) px[k] = float(acc[k] / wsum);
    } else if (dir) {
      lookup(src, *dir, px);
    } else if (const auto d = dst.texel_direction(c, r)) {
      lookup(src, *d, px);  // a sliver of the disc that no tap reached
    }
  };

  // The interpolated path (a lat-long source, bilinear): a texel's source positions and weights
  // are interpolated between the exact ones at its corners, checked against the exact ones at its
  // centre; taps read the ripmap level whose texels are square at that latitude, so a footprint
  // near a pole costs what it costs at the equator. A texel whose check fails (a pole, the
  // sphere map's rim) takes the exact path.
  std::optional<LatLongRipmap> ripmap;
  std::optional<PeakPyramid> peaks;
  if (interpolated) {
    ripmap.emplace(src);
    // The share of the map's energy above which a texel is rendered exactly: a tenth of the energy
    // tolerance (of the default's where it is off: the interpolated cell is an approximation even
    // when no extra taps are asked for), so that no knob's integral error grows against the
    // exact path's (docs/tradeoffs.md).
    peaks.emplace(magnitude, energy,
                  0.1 * (options.energy_tolerance > 0 ? options.energy_tolerance : ResampleOptions{}.energy_tolerance));
  }

  // Rows in ranges of 16, so that the interpolated path shares corner lines between rows.
  constexpr int kRange = 16;
  parallel_for_rows((dst.height() + kRange - 1) / kRange, [&](int range) {
    const int r0 = range * kRange, r1 = std::min(dst.height(), r0 + kRange);
    if (!ripmap) {
      for (int r = r0; r < r1; ++r)
        for (int c = 0; c < dst.width(); ++c) exact_texel(c, r, out.pixels.ptr<float>(r) + std::size_t(c) * ch);
    } else {
      interpolated_rows(src, dst, *ripmap, options, *peaks, r0, r1, out, exact_texel);
    }
    if (options.progress) {
      // Reported only from ranges that finish; the callback itself decides how often to draw.
      const int done = rows_done += r1 - r0;
      options.progress(double(done) / dst.height());
    }
  });
  return out;
}

}  // namespace rsibr
