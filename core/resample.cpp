#include "core/resample.h"

#include "core/latlong_ripmap.h"
#include "core/parallel.h"
#include "core/sphere_map.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <optional>
#include <vector>

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

// One destination row by interpolated taps from a lat-long source (see resample()). Corners are
// taken a hair inside the row so that a cube's face is the row's own; the interpolation's
// parameter across the row allows for that. exact(c, r, px) renders a texel the check refuses.
template <class Exact>
void interpolated_row(const EnvMap& src, const Layout& dst, const LatLongRipmap& ripmap, const ResampleOptions& options,
                      const PeakPyramid& peaks, int r, float* row, const Exact& exact) {
  constexpr double kInset = 1e-3;
  // Largest mismatch at the centre between interpolated and exact: source position (texels of
  // the level read) and relative density.
  constexpr double kPositionTolerance = 0.02, kDensityTolerance = 1e-3;
  const int width = dst.width(), ch = src.channels(), max_n = std::max(1, options.max_subsamples);
  std::vector<PointSample> top(std::size_t(width) + 1), bottom(std::size_t(width) + 1);
  for (int c = 0; c <= width; ++c) {
    top[std::size_t(c)] = point_sample(dst, src.layout, Vec2(c - 0.5, r - 0.5 + kInset));
    bottom[std::size_t(c)] = point_sample(dst, src.layout, Vec2(c - 0.5, r + 0.5 - kInset));
  }
  const double period = src.layout.width() - 1, dlat = ripmap.latitude_step();
  double acc[kMaxChannels];
  float tap[kMaxChannels];
  for (int c = 0; c < width; ++c) {
    float* px = row + std::size_t(c) * ch;
    const PointSample* k[4] = {&top[std::size_t(c)], &top[std::size_t(c) + 1], &bottom[std::size_t(c)],
                               &bottom[std::size_t(c) + 1]};
    const PointSample centre = point_sample(dst, src.layout, Vec2(c, r));
    if (!centre.ok || !k[0]->ok || !k[1]->ok || !k[2]->ok || !k[3]->ok) {
      exact(c, r, px);
      continue;
    }
    // Corner columns unwrapped to the centre's side of the seam.
    double x[4], y[4], w[4];
    for (int i = 0; i < 4; ++i) {
      x[i] = k[i]->x - period * std::round((k[i]->x - centre.x) / period);
      y[i] = k[i]->y;
      w[i] = k[i]->density;
    }
    const double lat = 0.5 * kPi - dlat * centre.y;
    const int level = ripmap.level_for_latitude(lat);
    const double level_columns = (ripmap.width(level) - 1) / period;  // level texels per level-0 texel
    const double mid_x = 0.25 * (x[0] + x[1] + x[2] + x[3]), mid_y = 0.25 * (y[0] + y[1] + y[2] + y[3]);
    const double mid_w = 0.25 * (w[0] + w[1] + w[2] + w[3]);
    if (std::abs(mid_x - centre.x) * level_columns > kPositionTolerance ||
        std::abs(mid_y - centre.y) > kPositionTolerance ||
        std::abs(mid_w - centre.density) > kDensityTolerance * centre.density) {
      exact(c, r, px);
      continue;
    }
    // The cell's largest angular extent: its edges and half diagonals (chords, radians).
    const double vertical = 1.0 / (1.0 - 2 * kInset);
    const double extent =
        std::max({(k[0]->dir - k[1]->dir).norm(), (k[2]->dir - k[3]->dir).norm(),
                  vertical * (k[0]->dir - k[2]->dir).norm(), vertical * (k[1]->dir - k[3]->dir).norm(),
                  std::sqrt(0.5) * (k[0]->dir - k[3]->dir).norm(), std::sqrt(0.5) * (k[1]->dir - k[2]->dir).norm()});
    const double step = std::min(dlat, ripmap.longitude_step(level) * std::abs(std::cos(lat)));
    const double footprint = step > 0 ? extent / step : double(max_n);
    const int n = std::clamp(int(std::ceil(options.supersampling * footprint - 1e-9)), 1, max_n);
    // A texel that may hold more than the energy tolerance of the whole map (a sun and its
    // neighbours: the brightest source texel anywhere in its footprint times its solid angle) takes
    // the exact path: the interpolated cell's small bulge against the true one would move a real
    // share of the map's energy.
    const double spread =
        std::max({std::abs(x[0] - x[3]), std::abs(x[1] - x[2]), std::abs(y[0] - y[3]), std::abs(y[1] - y[2])});
    if (peaks.bright(centre.x, centre.y, spread, centre.density)) {
      exact(c, r, px);
      continue;
    }
    if (n == 1) {
      ripmap.bilinear(level, centre.x, centre.y, px);
      continue;
    }
    for (int q = 0; q < ch; ++q) acc[q] = 0.0;
    double wsum = 0.0;
    for (int j = 0; j < n; ++j) {
      const double t = ((j + 0.5) / n - kInset) / (1.0 - 2 * kInset);  // 0 at the top corners, 1 at the bottom
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
  if (options.energy_tolerance > 0) {
    peak.layout = src.layout;
    magnitude.create(src.pixels.rows, src.pixels.cols, CV_32FC1);
    for (int r = 0; r < src.pixels.rows; ++r) {
      const float* p = src.pixels.ptr<float>(r);
      float* m = magnitude.ptr<float>(r);
      for (int c = 0; c < src.pixels.cols; ++c) {
        float v = 0;
        for (int k = 0; k < ch; ++k) v = std::max(v, std::isfinite(p[c * ch + k]) ? std::abs(p[c * ch + k]) : 0.f);
        m[c] = v;
      }
    }
    cv::dilate(magnitude, peak.pixels, cv::Mat::ones(3, 3, CV_8U));
    energy = integral(EnvMap{src.layout, magnitude, {}})[0];
  }
  // Taps per side a texel of this solid-angle density needs so that no tap carries more than the
  // energy tolerance of the whole map's energy (1 where the tolerance is off).
  const auto energy_taps = [&](const Vec3& dir, double density) {
    if (!(energy > 0)) return 1;
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
  if (src.layout.kind() == LayoutKind::LatLong && options.reconstruction == Reconstruction::Bilinear &&
      options.interpolate_taps) {
    ripmap.emplace(src);
    peaks.emplace(magnitude, energy, options.energy_tolerance);
  }

  parallel_for_rows(dst.height(), [&](int r) {
    float* row = out.pixels.ptr<float>(r);
    if (!ripmap) {
      for (int c = 0; c < dst.width(); ++c) exact_texel(c, r, row + std::size_t(c) * ch);
    } else {
      interpolated_row(src, dst, *ripmap, options, *peaks, r, row, exact_texel);
    }
    if (options.progress) {
      // Reported only from rows that finish; the callback itself decides how often to draw.
      const int done = ++rows_done;
      if (done % 16 == 0 || done == dst.height()) options.progress(double(done) / dst.height());
    }
  });
  return out;
}

}  // namespace rsibr
