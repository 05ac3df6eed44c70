#include "calib/extraction/occluded_light.h"

#include "core/luminance.h"
#include "core/parallel.h"
#include "core/sphere_map.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>

namespace rsibr {

namespace {

// The ray parameter where o + t d (d unit) first comes within the occluder: the sphere's entry
// point, or for a capsule the closest approach to its segment (the surface lies within its radius
// of it, near enough for a radiance lookup); nullopt when it misses.
std::optional<double> hit_distance(const Occluder& occ, const Vec3& o, const Vec3& d) {
  if (!ray_hits(occ, o, d)) return std::nullopt;
  if (occ.kind == Occluder::sphere) {
    const Vec3 oc = occ.centre - o;
    const double tc = oc.dot(d), h2 = occ.radius * occ.radius - (oc - tc * d).squaredNorm();
    return std::max(0.0, tc - std::sqrt(std::max(0.0, h2)));
  }
  // Closest approach of the ray to the segment's line, the segment parameter clamped.
  const Vec3 w = o - occ.centre;
  const double dd = d.dot(occ.axis), wd = w.dot(d), wa = w.dot(occ.axis);
  const double den = 1 - dd * dd;
  double t = den > 1e-12 ? (dd * wa - wd) / den : -wd;
  const double s = std::clamp(wa + t * dd, 0.0, occ.length);
  t = std::max(0.0, (occ.centre + s * occ.axis - o).dot(d));
  return t;
}

Vec3 pixel_rgb(const cv::Mat& m, int c, int r) {
  const cv::Vec3f v = m.at<cv::Vec3f>(r, c);
  return Vec3(v[0], v[1], v[2]);
}

// The probe's solid-angle-weighted mean over the fine texels it saw (weight >= min_weight), on a
// lat-long of `width` whose texels each hold an integer block of the probe's; a coarse texel is
// seen when over half of its solid angle was (0 where not).
struct AreaMean {
  EnvMap env;
  cv::Mat seen;  // CV_8UC1
};

AreaMean area_mean(const EnvMap& probe, const cv::Mat& weight, int width, double min_weight) {
  const Layout coarse(LayoutKind::LatLong, width, width / 2);
  AreaMean out{EnvMap::zeros(coarse), cv::Mat(coarse.height(), coarse.width(), CV_8UC1, cv::Scalar(0))};
  const int W = probe.layout.width(), H = probe.layout.height();
  cv::Mat sum(coarse.height(), coarse.width(), CV_64FC3, cv::Scalar::all(0));
  cv::Mat seen_sa(coarse.height(), coarse.width(), CV_64FC1, cv::Scalar(0));
  cv::Mat all_sa(coarse.height(), coarse.width(), CV_64FC1, cv::Scalar(0));
  const cv::Mat fine_sa = texel_solid_angles(probe.layout);
  for (int y = 0; y < H; ++y) {
    const int cy = std::min(coarse.height() - 1, y * coarse.height() / H);
    for (int x = 0; x < W; ++x) {
      const int cx = std::min(coarse.width() - 1, x * coarse.width() / W);
      const double sa = fine_sa.at<double>(y, x);
      all_sa.at<double>(cy, cx) += sa;
      if (!(weight.at<float>(y, x) >= min_weight)) continue;
      const cv::Vec3f v = probe.pixels.at<cv::Vec3f>(y, x);
      if (!(std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]))) continue;
      seen_sa.at<double>(cy, cx) += sa;
      cv::Vec3d& s = sum.at<cv::Vec3d>(cy, cx);
      for (int k = 0; k < 3; ++k) s[k] += sa * v[k];
    }
  }
  for (int y = 0; y < coarse.height(); ++y)
    for (int x = 0; x < coarse.width(); ++x) {
      const double s = seen_sa.at<double>(y, x);
      if (!(s > 0.5 * all_sa.at<double>(y, x))) continue;
      out.seen.at<unsigned char>(y, x) = 1;
      const cv::Vec3d v = sum.at<cv::Vec3d>(y, x) / s;
      out.env.pixels.at<cv::Vec3f>(y, x) = cv::Vec3f(float(v[0]), float(v[1]), float(v[2]));
    }
  return out;
}

}  // namespace

OpenLight open_light(const EnvMap& probe, const cv::Mat& weight, const Fresnel* fresnel, int width, double min_weight) {
  if (probe.layout.kind() != LayoutKind::LatLong || probe.pixels.type() != CV_32FC3)
    throw std::invalid_argument("open_light: the probe must be a lat-long RGB map");
  if (weight.type() != CV_32FC1 || weight.size() != probe.pixels.size())
    throw std::invalid_argument("open_light: the weight must be float, of the probe's size");
  if (width < 8 || width > probe.layout.width())
    throw std::invalid_argument(
        "open_light: the quadrature must be 8 texels wide or more, and no wider than the probe");
  OpenLight out;
  out.fresnel = fresnel;
  const Layout coarse(LayoutKind::LatLong, width, width / 2);
  out.env = EnvMap::zeros(coarse);
  out.fine = probe;
  out.fine_weight = weight;
  out.min_weight = min_weight;
  AreaMean mean = area_mean(probe, weight, width, min_weight);
  out.env.pixels = mean.env.pixels;
  out.seen = mean.seen;
  out.solid_angle = texel_solid_angles(coarse);
  // E_open at each texel's direction, over the seen texels (a lambert ball's unseen light is unknown).
  out.irradiance = EnvMap::zeros(coarse);
  std::vector<Vec3> dir(std::size_t(coarse.texel_count()));
  for (int y = 0; y < coarse.height(); ++y)
    for (int x = 0; x < coarse.width(); ++x)
      dir[std::size_t(y) * std::size_t(width) + std::size_t(x)] = *coarse.texel_direction(x, y);
  parallel_for_rows(coarse.height(), [&](int y) {
    for (int x = 0; x < coarse.width(); ++x) {
      const Vec3 n = dir[std::size_t(y) * std::size_t(width) + std::size_t(x)];
      Vec3 e = Vec3::Zero();
      for (int j = 0; j < coarse.height(); ++j)
        for (int i = 0; i < coarse.width(); ++i) {
          if (!out.seen.at<unsigned char>(j, i)) continue;
          const double c = n.dot(dir[std::size_t(j) * std::size_t(width) + std::size_t(i)]);
          if (c > 0) e += c * out.solid_angle.at<double>(j, i) * pixel_rgb(out.env.pixels, i, j);
        }
      out.irradiance.pixels.at<cv::Vec3f>(y, x) = cv::Vec3f(float(e[0]), float(e[1]), float(e[2]));
    }
  });
  return out;
}

OccludedLight occluded_light(const MapView& grey, const Mat3& world_from_cam, const BallCone& grey_cone,
                             const std::vector<OccluderLight>& occluders, const OpenLight& light, const MapView* chrome,
                             const Vec3& chrome_centre, const cv::Mat& chrome_hidden) {
  const Layout& q = light.env.layout;
  const int size_x = grey.rgb.cols, size_y = grey.rgb.rows;
  OccludedLight out;
  out.ratio = cv::Mat(size_y, size_x, CV_32FC3, cv::Scalar::all(1));
  // Quadrature nodes: seen directions in the camera frame, their weights and radiance.
  struct Node {
    Vec3 w_cam, w_world, L;
    double sa;
    int x, y;  // its quadrature cell
  };
  std::vector<Node> nodes;
  const Mat3 cam_from_world = world_from_cam.transpose();
  for (int y = 0; y < q.height(); ++y)
    for (int x = 0; x < q.width(); ++x) {
      if (!light.seen.at<unsigned char>(y, x)) continue;
      const Vec3 w = *q.texel_direction(x, y);
      nodes.push_back(
          {cam_from_world * w, w, pixel_rgb(light.env.pixels, x, y), light.solid_angle.at<double>(y, x), x, y});
    }
  if (nodes.empty() || occluders.empty()) return out;
  auto open_radiance = [&](const Vec3& w_world) {
    float v[3];
    sample_bilinear(light.env, w_world, v);
    return Vec3(v[0], v[1], v[2]);
  };
  const Vec3 centre = grey_cone.axis.normalized() / std::sin(grey_cone.half_angle);
  const Mat3 cam_from_view = cam_from_world * grey.world_from_view;
  // What the view's chrome ball sees beyond the far environment: per chrome texel, its radiance
  // (over F(cos_i)) minus the probe's in the same direction (the probe holds the far environment,
  // the photographer masked), summed per quadrature cell with the count of texels. Where nothing
  // stands the difference is resampling noise about 0; where the photographer stands it is his
  // radiance minus what he hides. A texel clipped in every bracket shows light, not a body: it
  // counts with a difference of 0, and so do the texels within 2 of one (a sun's glare and the
  // texels it partly covers, unclipped but far above the probe there, which would read as a body
  // brighter than the sky and darken the map). One hidden by another ball in front, or where the
  // probe saw nothing, does not count.
  // The probe is read at about the chrome texels' footprint (a texel of a size-s mirror map
  // subtends 4 / s rad on a side), an area mean as the texel is, not a point of its texture.
  EnvMap far;
  if (chrome) {
    const int W = light.fine.layout.width();
    int k = 1;
    while (W % (2 * k) == 0 && W / (2 * k) >= 8 && double(W) / (2 * k) >= kPi * chrome->rgb.cols / 2) k *= 2;
    far = area_mean(light.fine, light.fine_weight, W / k, light.min_weight).env;
  }
  cv::Mat beyond_sum(q.height(), q.width(), CV_64FC3, cv::Scalar::all(0));
  cv::Mat beyond_count(q.height(), q.width(), CV_32SC1, cv::Scalar(0));
  cv::Mat near_clipped;
  if (chrome && !chrome->clipped.empty()) {
    cv::Mat clipped = chrome->clipped > 0;
    cv::dilate(clipped, near_clipped, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(5, 5)));
  }
  // No diffuse body is brighter than a white one facing the brightest irradiance, E_max / pi: a
  // chrome texel above it shows a light (a lamp the probe's area mean spreads or places a fraction
  // of a degree off), not a body, and counts with a difference of 0; a few such texels would
  // otherwise darken the map without bound (L + D has no ceiling, while a body hiding a light
  // takes at most L). The bound is taken 4x higher, for light the probe lacks: on the process
  // test's shoot with its photographer, 1x / 2x / 4x gave a worst grey view of 0.131 / 0.105 /
  // 0.097 stops, and without him 0.044 / 0.052 / 0.054.
  constexpr double kBodyMargin = 4;
  double brightest_body = INFINITY;
  if (chrome) {
    double e_max = 0;
    for (int y = 0; y < light.irradiance.pixels.rows; ++y)
      for (int x = 0; x < light.irradiance.pixels.cols; ++x)
        e_max = std::max(e_max, luminance(pixel_rgb(light.irradiance.pixels, x, y)));
    if (e_max > 0) brightest_body = kBodyMargin * e_max / kPi;
  }
  // The difference at texel (c, r), or nullopt where it does not count.
  auto beyond_far = [&](int c, int r) -> std::optional<Vec3> {
    if (c < 0 || r < 0 || c >= chrome->rgb.cols || r >= chrome->rgb.rows) return std::nullopt;
    const Vec2 xy = sphere_map::disc_from_pixel(Vec2(c, r), chrome->rgb.cols, chrome->rgb.rows);
    if (xy.squaredNorm() >= 1) return std::nullopt;
    if (!chrome_hidden.empty() && chrome_hidden.at<unsigned char>(r, c)) return std::nullopt;
    if (!near_clipped.empty() && near_clipped.at<unsigned char>(r, c)) return Vec3(Vec3::Zero());
    Vec3 v = pixel_rgb(chrome->rgb, c, r);
    if (!(v.maxCoeff() > 0) || !v.allFinite()) return std::nullopt;
    if (light.fresnel)
      v = v.cwiseQuotient(light.fresnel->eval(sphere_map::g_normal(xy).z()).cwiseMax(Vec3::Constant(1e-3)));
    if (luminance(v) > brightest_body) return Vec3(Vec3::Zero());
    float f[3];
    sample_bilinear(far, chrome->world_from_view * sphere_map::g_mirror(xy), f);
    const Vec3 probe(f[0], f[1], f[2]);
    if (!(probe.maxCoeff() > 0) || !probe.allFinite()) return std::nullopt;
    return Vec3(v - probe);
  };
  if (chrome) {
    const int cw = chrome->rgb.cols, ch = chrome->rgb.rows;
    for (int r = 0; r < ch; ++r)
      for (int c = 0; c < cw; ++c) {
        const std::optional<Vec3> d = beyond_far(c, r);
        if (!d) continue;
        const Vec2 xy = sphere_map::disc_from_pixel(Vec2(c, r), cw, ch);
        const Vec2 px = q.pixel(chrome->world_from_view * sphere_map::g_mirror(xy));
        const int x = std::clamp(int(std::floor(px.x() + 0.5)), 0, q.width() - 1);
        const int y = std::clamp(int(std::floor(px.y() + 0.5)), 0, q.height() - 1);
        ++beyond_count.at<int>(y, x);
        cv::Vec3d& acc = beyond_sum.at<cv::Vec3d>(y, x);
        for (int k = 0; k < 3; ++k) acc[k] += (*d)[k];
      }
  }
  // The radiance an occluder sends back along -w from the hit point h (camera frame, grey radii);
  // nullopt: not known (the direction then restores nothing).
  auto occluder_radiance = [&](const OccluderLight& o, const Vec3& h, const Vec3& w,
                               const Node& node) -> std::optional<Vec3> {
    if (o.source == OccluderLight::mirror_ball || o.source == OccluderLight::lambert_ball) {
      const Vec3 m = (h - o.shape.centre).normalized();
      if (o.source == OccluderLight::lambert_ball) {
        float v[3];
        sample_bilinear(light.irradiance, world_from_cam * m, v);
        return o.albedo / kPi * Vec3(v[0], v[1], v[2]);
      }
      const double cos_i = std::clamp(-w.dot(m), 0.0, 1.0);
      const Vec3 r = w + 2 * cos_i * m;
      const Vec3 F = light.fresnel ? light.fresnel->eval(cos_i) : Vec3::Ones();
      return Vec3(F.cwiseProduct(open_radiance(world_from_cam * r)));
    }
    if (!chrome) return std::nullopt;
    // The chrome ball's view toward the hit point h (the ray's closest approach to the capsule's
    // axis, where a body stands), u: what it sees there beyond the far environment, D(u), is what
    // a body at h adds to this ball's ray along w, so L_s(w) = L(w) + D(u) (the mean of u's cell).
    // Where nothing stands, D is noise about 0, so the capsule's empty parts restore nothing on
    // average. Where a body stands, L_s = body + L(w) - L(u): exact when the environment behind
    // it is alike from both balls. (A threshold on D, taking the body's radiance where it is
    // large, flagged a fifth of the texels outside any body on textured environments; reading
    // the chrome ball along w itself made a head in front of a sun for the chrome ball, ~8 degrees
    // of parallax away for balls 14 cm apart at 1 m, block the sun for this ball too.)
    const Vec3 u = (h - chrome_centre).normalized();
    // Where this ball stands in the chrome ball's way toward h, the chrome ball sees this ball
    // there, not the occluder (a margin for its surface point off its centre).
    Occluder self;
    self.centre = centre;
    self.radius = 1.15;
    if (ray_hits(self, chrome_centre, u)) return std::nullopt;
    const Vec3 u_world = world_from_cam * u;
    const Vec2 qp = q.pixel(u_world);
    const int ux = std::clamp(int(std::floor(qp.x() + 0.5)), 0, q.width() - 1);
    const int uy = std::clamp(int(std::floor(qp.y() + 0.5)), 0, q.height() - 1);
    std::optional<Vec3> d;
    if (const int n = beyond_count.at<int>(uy, ux); n > 0) {
      const cv::Vec3d v = beyond_sum.at<cv::Vec3d>(uy, ux) / double(n);
      d = Vec3(v[0], v[1], v[2]);
    } else {
      // A cell smaller than the chrome map's texels (toward the poles): the texel of u.
      const Vec3 r_view = chrome->world_from_view.transpose() * u_world;
      const Vec2 px = sphere_map::pixel_from_disc(sphere_map::g_mirror_inv(r_view), chrome->rgb.cols, chrome->rgb.rows);
      d = beyond_far(int(std::lround(px.x())), int(std::lround(px.y())));
    }
    if (!d) return std::nullopt;
    return Vec3((node.L + *d).cwiseMax(Vec3::Zero()));
  };
  // Pass 1: the open and the scene's irradiance of every texel of the disc.
  cv::Mat e_open_map(size_y, size_x, CV_64FC3, cv::Scalar::all(0)),
      e_scene_map(size_y, size_x, CV_64FC3, cv::Scalar::all(0));
  parallel_for_rows(size_y, [&](int row) {
    for (int col = 0; col < size_x; ++col) {
      const Vec2 xy = sphere_map::disc_from_pixel(Vec2(col, row), size_x, size_y);
      if (xy.squaredNorm() >= 1) continue;
      const Vec3 n = cam_from_view * sphere_map::g_normal(xy);
      const Vec3 p = centre + n;
      Vec3 e_open = Vec3::Zero(), e_scene = Vec3::Zero();
      for (const Node& node : nodes) {
        const double c = n.dot(node.w_cam);
        if (!(c > 0)) continue;
        const double wgt = c * node.sa;
        // The nearest occluder on the ray, and what it sends.
        double best = INFINITY;
        std::optional<Vec3> sent;
        bool hit = false;
        for (const OccluderLight& o : occluders) {
          const auto t = hit_distance(o.shape, p, node.w_cam);
          if (!t || *t >= best) continue;
          best = *t;
          hit = true;
          sent = occluder_radiance(o, p + *t * node.w_cam, node.w_cam, node);
        }
        const Vec3 Ls = hit && sent ? *sent : node.L;
        e_open += wgt * node.L;
        e_scene += wgt * Ls;
      }
      e_open_map.at<cv::Vec3d>(row, col) = cv::Vec3d(e_open[0], e_open[1], e_open[2]);
      e_scene_map.at<cv::Vec3d>(row, col) = cv::Vec3d(e_scene[0], e_scene[1], e_scene[2]);
    }
  });
  // The map's scale per channel, k = captured / E_scene (albedo / pi times the exposure): the median
  // over the confident texels.
  auto confidence = [&](int row, int col) {
    return grey.confidence.empty() ? 1.0 : double(grey.confidence.at<float>(row, col));
  };
  Vec3 scale = Vec3::Zero();
  for (int k = 0; k < 3; ++k) {
    std::vector<double> v;
    for (int row = 0; row < size_y; ++row)
      for (int col = 0; col < size_x; ++col) {
        const double e = e_scene_map.at<cv::Vec3d>(row, col)[k], g = grey.rgb.at<cv::Vec3f>(row, col)[k];
        if (confidence(row, col) > 0 && e > 0 && g > 0 && std::isfinite(g)) v.push_back(g / e);
      }
    if (v.empty()) continue;
    std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(v.size() / 2), v.end());
    scale[k] = v[v.size() / 2];
  }
  // Pass 2: the ratio. Where the model explains the texel (captured ~ k E_scene) it is
  // E_open / E_scene, exact whatever the albedo; where it does not (a sun's terminator, which a
  // quadrature cell of ~6 degrees places coarsely: there the texel holds sunlight the model gives
  // it none of, and a bright photographer's share would look several times larger than it is),
  // the difference is added in the map's own scale, 1 + k (E_open - E_scene) / captured. Between
  // a misfit of 1.25x and 2x the two are blended.
  const double hi = std::exp2(out.clamp_stops), lo = 1 / hi;
  std::vector<double> row_sum(std::size_t(size_y), 0), row_max(std::size_t(size_y), 0), row_w(std::size_t(size_y), 0);
  parallel_for_rows(size_y, [&](int row) {
    for (int col = 0; col < size_x; ++col) {
      const Vec2 xy = sphere_map::disc_from_pixel(Vec2(col, row), size_x, size_y);
      if (xy.squaredNorm() >= 1) continue;
      const cv::Vec3d eo = e_open_map.at<cv::Vec3d>(row, col), es = e_scene_map.at<cv::Vec3d>(row, col);
      const cv::Vec3f g = grey.rgb.at<cv::Vec3f>(row, col);
      Vec3 ratio = Vec3::Ones();
      for (int k = 0; k < 3; ++k) {
        if (!(eo[k] > 0 && es[k] > 0)) continue;
        double r = eo[k] / es[k];
        if (scale[k] > 0 && g[k] > 0 && std::isfinite(g[k])) {
          const double misfit = std::abs(std::log(g[k] / (scale[k] * es[k])));
          const double x = std::clamp((misfit - std::log(1.25)) / (std::log(2.0) - std::log(1.25)), 0.0, 1.0);
          const double t = x * x * (3 - 2 * x);
          r = (1 - t) * r + t * (1 + scale[k] * (eo[k] - es[k]) / g[k]);
        }
        ratio[k] = std::clamp(r, lo, hi);
      }
      out.ratio.at<cv::Vec3f>(row, col) = cv::Vec3f(float(ratio[0]), float(ratio[1]), float(ratio[2]));
      const double conf = confidence(row, col);
      if (conf > 0) {
        const Vec3 before(g[0], g[1], g[2]);
        const double y0 = luminance(before), y1 = luminance(Vec3(before.cwiseProduct(ratio)));
        const double stops = y0 > 0 && y1 > 0 && std::isfinite(y0) ? std::abs(std::log2(y1 / y0)) : 0.0;
        row_sum[std::size_t(row)] += conf * stops;
        row_w[std::size_t(row)] += conf;
        row_max[std::size_t(row)] = std::max(row_max[std::size_t(row)], stops);
      }
    }
  });
  double s = 0, w = 0;
  for (int r = 0; r < size_y; ++r) {
    s += row_sum[std::size_t(r)], w += row_w[std::size_t(r)];
    out.max_stops = std::max(out.max_stops, row_max[std::size_t(r)]);
  }
  out.mean_stops = w > 0 ? s / w : 0;
  return out;
}

void restore_occluded_light(MapView& grey, const OccludedLight& r) {
  if (r.ratio.size() != grey.rgb.size())
    throw std::invalid_argument("restore_occluded_light: the ratio is not of the map's size");
  cv::multiply(grey.rgb, r.ratio, grey.rgb);
}

}  // namespace rsibr
