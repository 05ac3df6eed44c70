#include "calib/extraction/sphere_map_extraction.h"

#include "core/parallel.h"
#include "hdr/merge.h"
#include "core/sphere_map.h"
#include "core/luminance.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace rsibr {

namespace {

// Samples this close to 0 (radiance units) do not count as a feature against the texel's others.
constexpr double kSampleFloor = 1e-12;

double smoothstep(double e0, double e1, double x) {
  const double t = std::clamp((x - e0) / (e1 - e0), 0.0, 1.0);
  return t * t * (3 - 2 * t);
}

// F(n) = normalize(w(n) + r) - n with w(n) = -(C + n)/|C + n|, on the tangent plane of n0.
Vec3 half_residual(const Vec3& centre, const Vec3& r, const Vec3& n) {
  const Vec3 w = -(centre + n).normalized();
  return (w + r).normalized() - n;
}

}  // namespace

// Newton on u in R^2, n(u) = normalize(n0 + u1 t1 + u2 t2), residual G(u) = [t1 t2]^T F(n(u)); the
// 2x2 Jacobian by central differences. Guard: a step that does not lower |F| is halved (10 times).
std::optional<Vec3> reflection_normal(const Vec3& centre, const Vec3& r, const Vec3& start) {
  const Vec3 n0 = start.normalized();
  const Vec3 t1 = n0.unitOrthogonal(), t2 = n0.cross(t1);
  auto normal = [&](const Eigen::Vector2d& u) { return (n0 + u(0) * t1 + u(1) * t2).normalized(); };
  auto g = [&](const Eigen::Vector2d& u) {
    const Vec3 f = half_residual(centre, r, normal(u));
    return Eigen::Vector2d(f.dot(t1), f.dot(t2));
  };
  Eigen::Vector2d u = Eigen::Vector2d::Zero();
  Eigen::Vector2d gu = g(u);
  for (int it = 0; it < 30; ++it) {
    if (gu.norm() < 1e-12) return normal(u);
    const double h = 1e-7;
    Eigen::Matrix2d j;
    for (int k = 0; k < 2; ++k) {
      Eigen::Vector2d e = Eigen::Vector2d::Zero();
      e(k) = h;
      j.col(k) = (g(u + e) - g(u - e)) / (2 * h);
    }
    Eigen::Vector2d step = j.fullPivLu().solve(-gu);
    if (!step.allFinite()) return std::nullopt;
    bool improved = false;
    for (int halve = 0; halve < 10; ++halve) {
      const Eigen::Vector2d gn = g(u + step);
      if (gn.norm() < gu.norm()) {
        u += step;
        gu = gn;
        improved = true;
        break;
      }
      step *= 0.5;
    }
    if (!improved) break;
  }
  if (gu.norm() < 1e-9) return normal(u);
  return std::nullopt;
}

MapView extract_sphere_map(const cv::Mat& image, const cv::Mat& flags, const LensModel& lens, const BallCone& cone,
                           const Mat3& world_from_cam, const ExtractOptions& options, cv::Mat* hidden) {
  if (image.type() != CV_32FC3 || image.cols != lens.width() || image.rows != lens.height())
    throw std::invalid_argument("extract: the image must be float RGB of the lens model's size (" +
                                std::to_string(lens.width()) + "x" + std::to_string(lens.height()) + ")");
  if (!flags.empty() && (flags.type() != CV_8UC1 || flags.size() != image.size()))
    throw std::invalid_argument("extract: the flags must be 8-bit, one channel, of the image's size");
  if (!(cone.half_angle > 0 && cone.half_angle < kPi / 2) || !cone.axis.allFinite())
    throw std::invalid_argument("extract: invalid ball cone");
  if (options.size < 2) throw std::invalid_argument("extract: map size must be >= 2");

  const Vec3 axis = cone.axis.normalized();
  const Mat3 cam_from_view = world_from_view_for(-axis, Vec3(0, -1, 0));
  const Vec3 centre = axis / std::sin(cone.half_angle);
  const double cos_cam_zero = std::cos(options.camera_mask_deg * kPi / 180);
  const double cos_cam_full = std::cos((options.camera_mask_deg + options.camera_ramp_deg) * kPi / 180);
  const double cos_stand_zero = std::cos(options.stand_mask_deg * kPi / 180);
  const double cos_stand_full = std::cos((options.stand_mask_deg + options.stand_ramp_deg) * kPi / 180);
  const double cos_rim_zero = std::cos(options.rim_zero_deg * kPi / 180);
  const double cos_rim_full = std::cos(options.rim_full_deg * kPi / 180);
  const Vec3 to_camera = -axis;  // from the ball centre
  // Pixels per radian across the outline (at one limb ray; the scale varies slowly over a ball).
  const double limb_scale = pixels_per_radian(
      lens, axis, std::cos(cone.half_angle) * axis + std::sin(cone.half_angle) * axis.unitOrthogonal());
  const int size = options.size;

  MapView mv;
  mv.world_from_view = world_from_cam * cam_from_view;
  mv.view = mv.world_from_view.col(2);
  mv.warp = options.mirror ? CentralDirection::Mirror : CentralDirection::Normal;
  mv.source = MapSource::Captured;
  mv.material = options.material;
  mv.attributes["indexing"] = options.indexing == SphereIndexing::reflection ? "reflection" : "orthographic";
  // The texels across the disc where they were measured: the ball's image diameter in pixels (its
  // angular diameter times the pixels per radian at the outline). A map larger than this is an
  // upsampling; the runtime's MIP-mask blend prefers sharper sources (runtime/blend_engine.h).
  mv.attributes["nativeSize"] = std::to_string(2.0 * cone.half_angle * limb_scale);
  mv.rgb = cv::Mat(size, size, CV_32FC3, cv::Scalar::all(0));
  mv.confidence = cv::Mat(size, size, CV_32FC1, cv::Scalar(0));
  if (!flags.empty()) mv.clipped = cv::Mat(size, size, CV_32FC1, cv::Scalar(0));
  if (hidden) *hidden = cv::Mat(size, size, CV_8UC1, cv::Scalar(0));

  // One sample: the disc point's surface normal (start: the guess for the reflection solve), its
  // image point, and the incidence cosine; false when it has none (outside the disc or the image,
  // facing away, no reflection solution).
  struct Sample {
    Vec3 n, reflected;
    Vec2 px;
    double cos_i = 0;
  };
  auto sample_at = [&](const Vec2& xy, const Vec3* start, Sample* out) {
    if (xy.squaredNorm() >= 1.0) return false;
    Vec3 n = cam_from_view * sphere_map::g_normal(xy);
    Vec3 reflected = Vec3::Zero();  // the direction the point reflects the camera ray into (camera frame)
    if (options.indexing == SphereIndexing::reflection) {
      const Vec3 r = cam_from_view * sphere_map::g_mirror(xy);
      const auto solved = reflection_normal(centre, r, start ? *start : n);
      if (!solved) return false;
      n = *solved;
      reflected = r;
    }
    const Vec3 p = centre + n;
    const Vec3 w = -p.normalized();  // toward the camera
    const double cos_i = w.dot(n);
    if (!(cos_i > 0)) return false;
    if (options.indexing == SphereIndexing::orthographic) reflected = 2 * cos_i * n - w;
    const Vec2 px = lens.project(p);
    if (!px.allFinite() || !lens.in_image(px, 0.5)) return false;
    if (!flags.empty() && (flags.at<unsigned char>(std::clamp(int(std::lround(px.y())), 0, flags.rows - 1),
                                                   std::clamp(int(std::lround(px.x())), 0, flags.cols - 1)) &
                           kOutside))
      return false;  // beyond the photo on a view's canvas: not seen
    *out = {n, reflected, px, cos_i};
    return true;
  };
  // Bilinear taps (pixel centres at integers): the value, and whether a tap is clipped.
  auto read = [&](const Vec2& px, Vec3* value) {
    const int x0 = std::clamp(static_cast<int>(std::floor(px.x())), 0, image.cols - 2);
    const int y0 = std::clamp(static_cast<int>(std::floor(px.y())), 0, image.rows - 2);
    const double fx = std::clamp(px.x() - x0, 0.0, 1.0), fy = std::clamp(px.y() - y0, 0.0, 1.0);
    bool clipped = false;
    if (!flags.empty()) {
      const unsigned char f = flags.at<unsigned char>(y0, x0) | flags.at<unsigned char>(y0, x0 + 1) |
                              flags.at<unsigned char>(y0 + 1, x0) | flags.at<unsigned char>(y0 + 1, x0 + 1);
      clipped = (f & options.clipped_mask) != 0;
    }
    const cv::Vec3f a = image.at<cv::Vec3f>(y0, x0), b = image.at<cv::Vec3f>(y0, x0 + 1);
    const cv::Vec3f c = image.at<cv::Vec3f>(y0 + 1, x0), d = image.at<cv::Vec3f>(y0 + 1, x0 + 1);
    for (int k = 0; k < 3; ++k)
      (*value)[k] = (1 - fy) * ((1 - fx) * a[k] + fx * b[k]) + fy * ((1 - fx) * c[k] + fx * d[k]);
    return clipped;
  };

  // Texel centres first (their image points give each texel's footprint).
  std::vector<Sample> centres(std::size_t(size) * std::size_t(size));
  std::vector<char> valid(centres.size(), 0);
  parallel_for_rows(size, [&](int row) {
    for (int col = 0; col < size; ++col) {
      const std::size_t i = std::size_t(row) * std::size_t(size) + std::size_t(col);
      valid[i] = sample_at(sphere_map::disc_from_pixel(Vec2(col, row), size, size), nullptr, &centres[i]);
    }
  });
  auto footprint_px = [&](int row, int col) {
    const std::size_t i = std::size_t(row) * std::size_t(size) + std::size_t(col);
    double f = 0;
    for (const auto& [dr, dc] : {std::pair{0, 1}, {1, 0}, {0, -1}, {-1, 0}}) {
      const int r2 = row + dr, c2 = col + dc;
      if (r2 < 0 || c2 < 0 || r2 >= size || c2 >= size) continue;
      const std::size_t j = std::size_t(r2) * std::size_t(size) + std::size_t(c2);
      if (valid[j]) f = std::max(f, (centres[j].px - centres[i].px).norm());
    }
    return f;
  };

  parallel_for_rows(size, [&](int row) {
    for (int col = 0; col < size; ++col) {
      const std::size_t i = std::size_t(row) * std::size_t(size) + std::size_t(col);
      if (!valid[i]) continue;
      const Sample& s = centres[i];
      const Vec3 p = centre + s.n;
      double conf = smoothstep(cos_rim_zero, cos_rim_full, s.cos_i);
      const double limb_px = (cone.half_angle - angle_between(p, axis)) * limb_scale;
      conf *= smoothstep(options.limb_margin_px / 3, options.limb_margin_px, limb_px);
      if (options.mirror && options.camera_mask_deg > 0)
        conf *= smoothstep(cos_cam_zero, cos_cam_full, s.reflected.dot(to_camera));
      for (const Occluder& occ : options.in_front)
        if (ray_hits(occ, Vec3::Zero(), p.normalized(), p.norm())) {
          conf = 0;
          if (hidden) hidden->at<unsigned char>(row, col) = 1;
        }
      if (options.mirror)
        for (const Occluder& occ : options.occluders)
          if (ray_hits(occ, p, s.reflected.normalized())) conf = 0;
      if (options.down) {
        const Vec3 dir = options.mirror ? s.reflected : s.n;
        conf *= smoothstep(cos_stand_zero, cos_stand_full, dir.dot(options.down->normalized()));
      }
      int k = 1;
      if (options.mirror && options.supersample_spacing_px > 0)
        k = std::clamp(int(std::ceil(footprint_px(row, col) / options.supersample_spacing_px)), 1,
                       std::max(1, options.max_supersample));
      Vec3 v;
      bool clipped = read(s.px, &v);
      if (k > 1) {
        Vec3 sum = Vec3::Zero(), value;
        double lo = INFINITY, hi = 0;
        int count = 0;
        for (int a = 0; a < k; ++a)
          for (int b = 0; b < k; ++b) {
            const Vec2 q(col - 0.5 + (b + 0.5) / k, row - 0.5 + (a + 0.5) / k);
            Sample t;
            if (!sample_at(sphere_map::disc_from_pixel(q, size, size), &s.n, &t)) continue;
            // Samples whose taps reach past the outline read the background: left out.
            if ((cone.half_angle - angle_between(centre + t.n, axis)) * limb_scale < options.limb_margin_px) continue;
            clipped = read(t.px, &value) || clipped;
            sum += value;
            const double y = luminance(value);
            lo = std::min(lo, y), hi = std::max(hi, y);
            ++count;
          }
        // A feature smaller than the texel (the samples differ by more than 2x): their mean, which
        // keeps its energy. Elsewhere the centre's value, the point the texel stands for (the mean
        // of smooth content differs from it at second order, by the curvature over the texel).
        if (count > 0 && hi > 2 * lo + kSampleFloor) v = sum / count;
      }
      if (!v.allFinite()) continue;
      mv.rgb.at<cv::Vec3f>(row, col) = cv::Vec3f(float(v[0]), float(v[1]), float(v[2]));
      mv.confidence.at<float>(row, col) = clipped ? 0.f : static_cast<float>(conf);
      if (clipped) mv.clipped.at<float>(row, col) = static_cast<float>(conf);
    }
  });
  return mv;
}

}  // namespace rsibr
