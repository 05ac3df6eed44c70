#include "calib/occluded_light.h"

#include "core/luminance.h"
#include "core/parallel.h"
#include "core/sphere_map.h"

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
  out.seen = cv::Mat(coarse.height(), coarse.width(), CV_8UC1, cv::Scalar(0));
  out.solid_angle = texel_solid_angles(coarse);
  // Solid-angle-weighted mean of the fine texels the probe saw, per coarse texel; a coarse texel
  // is seen when over half of its solid angle was.
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
  // One chrome texel's radiance over F(cos_i), or nullopt where it is not filled, clipped (a lower
  // bound) or shows another ball in front.
  auto chrome_texel = [&](int c, int r, double cos_i) -> std::optional<Vec3> {
    if (c < 0 || r < 0 || c >= chrome->rgb.cols || r >= chrome->rgb.rows) return std::nullopt;
    if (!chrome_hidden.empty() && chrome_hidden.at<unsigned char>(r, c)) return std::nullopt;
    if (!chrome->clipped.empty() && chrome->clipped.at<float>(r, c) > 0) return std::nullopt;
    const Vec3 v = pixel_rgb(chrome->rgb, c, r);
    if (!(v.maxCoeff() > 0) || !v.allFinite()) return std::nullopt;
    if (!light.fresnel) return v;
    return Vec3(v.cwiseQuotient(light.fresnel->eval(cos_i).cwiseMax(Vec3::Constant(1e-3))));
  };
  // What the view's chrome ball sees, as the quadrature's cells: the mean of its texels whose
  // mirror direction falls in each cell (a mirror map's texels subtend equal solid angles about its
  // centre, dw = 4 dx dy), so that it is an area mean as the probe's cells are.
  cv::Mat chrome_sum(q.height(), q.width(), CV_64FC3, cv::Scalar::all(0));
  cv::Mat chrome_count(q.height(), q.width(), CV_32SC1, cv::Scalar(0));
  if (chrome) {
    const int cw = chrome->rgb.cols, ch = chrome->rgb.rows;
    for (int r = 0; r < ch; ++r)
      for (int c = 0; c < cw; ++c) {
        const Vec2 xy = sphere_map::disc_from_pixel(Vec2(c, r), cw, ch);
        if (xy.squaredNorm() >= 1) continue;
        const std::optional<Vec3> v = chrome_texel(c, r, sphere_map::g_normal(xy).z());
        if (!v) continue;
        const Vec2 px = q.pixel(chrome->world_from_view * sphere_map::g_mirror(xy));
        const int x = std::clamp(int(std::floor(px.x() + 0.5)), 0, q.width() - 1);
        const int y = std::clamp(int(std::floor(px.y() + 0.5)), 0, q.height() - 1);
        cv::Vec3d& acc = chrome_sum.at<cv::Vec3d>(y, x);
        for (int k = 0; k < 3; ++k) acc[k] += (*v)[k];
        ++chrome_count.at<int>(y, x);
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
    // The chrome ball's cell of the ray's own direction: where the capsule is empty it shows the
    // far environment there, and the photographer is far enough for the parallax between the two
    // balls to be a few degrees. Where this ball stands in the chrome ball's way along w, the
    // chrome ball sees this ball there, not the occluder (a margin for its surface point off its centre).
    Occluder self;
    self.centre = centre;
    self.radius = 1.15;
    if (ray_hits(self, chrome_centre, w)) return std::nullopt;
    if (const int n = chrome_count.at<int>(node.y, node.x); n > 0) {
      const cv::Vec3d v = chrome_sum.at<cv::Vec3d>(node.y, node.x) / double(n);
      return Vec3(v[0], v[1], v[2]);
    }
    // A cell smaller than the chrome map's texels (toward the poles): the texel of w.
    const Vec3 r_view = chrome->world_from_view.transpose() * (world_from_cam * w);
    const Vec2 px = sphere_map::pixel_from_disc(sphere_map::g_mirror_inv(r_view), chrome->rgb.cols, chrome->rgb.rows);
    // Mirror direction r = 2 (n.z) n - z, so n.z = sqrt((1 + r.z) / 2).
    return chrome_texel(int(std::lround(px.x())), int(std::lround(px.y())),
                        std::sqrt(std::clamp(0.5 * (1 + r_view.z()), 1e-6, 1.0)));
  };
  const double hi = std::exp2(out.clamp_stops), lo = 1 / hi;
  std::vector<double> row_sum(std::size_t(size_y), 0), row_max(std::size_t(size_y), 0), row_w(std::size_t(size_y), 0);
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
      Vec3 ratio = Vec3::Ones();
      for (int k = 0; k < 3; ++k)
        if (e_open[k] > 0 && e_scene[k] > 0) ratio[k] = std::clamp(e_open[k] / e_scene[k], lo, hi);
      out.ratio.at<cv::Vec3f>(row, col) = cv::Vec3f(float(ratio[0]), float(ratio[1]), float(ratio[2]));
      const double conf = grey.confidence.empty() ? 1.0 : grey.confidence.at<float>(row, col);
      if (conf > 0) {
        const double y_open = luminance(e_open), y_scene = luminance(e_scene);
        const double stops = y_open > 0 && y_scene > 0 ? std::abs(std::log2(y_open / y_scene)) : 0.0;
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
