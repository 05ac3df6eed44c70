#include "calib/orientation/rotation_search.h"

#include "calib/orientation/ball_cube_features.h"
#include "core/parallel.h"
#include "hdr/merge.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace rsibr {

Vec3 panorama_direction(const PanoramaLevel& level, double u, double v) {
  const double theta = kPi * (v + 0.5) / level.height, phi = 2 * kPi * (u + 0.5) / level.width - kPi;
  return Vec3(std::sin(theta) * std::sin(phi), -std::cos(theta), std::sin(theta) * std::cos(phi));
}

Vec2 panorama_texel(const PanoramaLevel& level, const Vec3& d) {
  const double theta = std::acos(std::clamp(-d.y() / d.norm(), -1.0, 1.0)), phi = std::atan2(d.x(), d.z());
  return Vec2((phi + kPi) / (2 * kPi) * level.width - 0.5, theta / kPi * level.height - 0.5);
}

namespace {

float luminance_at(const cv::Mat& image, const cv::Mat& flags, const Vec2& q, bool* ok) {
  const int x0 = std::clamp(static_cast<int>(std::floor(q.x())), 0, image.cols - 2);
  const int y0 = std::clamp(static_cast<int>(std::floor(q.y())), 0, image.rows - 2);
  const double fx = std::clamp(q.x() - x0, 0.0, 1.0), fy = std::clamp(q.y() - y0, 0.0, 1.0);
  if (!flags.empty() && ((flags.at<unsigned char>(y0, x0) | flags.at<unsigned char>(y0, x0 + 1) |
                          flags.at<unsigned char>(y0 + 1, x0) | flags.at<unsigned char>(y0 + 1, x0 + 1)) &
                         kOutside)) {
    *ok = false;
    return 0;
  }
  auto lum = [&](int x, int y) {
    const cv::Vec3f p = image.at<cv::Vec3f>(y, x);
    return (double(p[0]) + p[1] + p[2]) / 3;
  };
  const double l = (1 - fy) * ((1 - fx) * lum(x0, y0) + fx * lum(x0 + 1, y0)) +
                   fy * ((1 - fx) * lum(x0, y0 + 1) + fx * lum(x0 + 1, y0 + 1));
  *ok = std::isfinite(l);
  return *ok ? static_cast<float>(std::max(l, 0.0)) : 0.f;
}

PanoramaLevel half_size(const PanoramaLevel& f) {
  PanoramaLevel c;
  c.width = f.width / 2, c.height = f.height / 2;
  c.value.assign(std::size_t(c.width) * c.height, 0.f);
  c.weight.assign(c.value.size(), 0.f);
  for (int v = 0; v < c.height; ++v)
    for (int u = 0; u < c.width; ++u) {
      double w = 0, wv = 0;
      for (int dv = 0; dv < 2; ++dv)
        for (int du = 0; du < 2; ++du) {
          const std::size_t i = std::size_t(2 * v + dv) * f.width + 2 * u + du;
          w += f.weight[i], wv += double(f.weight[i]) * f.value[i];
        }
      const std::size_t j = std::size_t(v) * c.width + u;
      c.weight[j] = static_cast<float>(w / 4);
      c.value[j] = w > 0 ? static_cast<float>(wv / w) : 0.f;
    }
  return c;
}

// Per level of `a`: the direction of every texel and its solid-angle weight (sin theta).
struct LevelGeometry {
  std::vector<Vec3> dir;
  std::vector<double> area;
  double sphere = 0;  // sum of area over every texel
};

LevelGeometry geometry_of(const PanoramaLevel& level) {
  LevelGeometry g;
  for (int v = 0; v < level.height; ++v)
    for (int u = 0; u < level.width; ++u) {
      g.dir.push_back(panorama_direction(level, u, v));
      g.area.push_back(std::sin(kPi * (v + 0.5) / level.height));
      g.sphere += g.area.back();
    }
  return g;
}

double correlate(const PanoramaLevel& a, const LevelGeometry& ga, const PanoramaLevel& b, const Mat3& r,
                 double* overlap) {
  double sw = 0, sa = 0, sb = 0, saa = 0, sbb = 0, sab = 0;
  const int w = b.width, h = b.height;
  for (std::size_t i = 0; i < a.weight.size(); ++i) {
    if (!(a.weight[i] > 0)) continue;
    const Vec2 t = panorama_texel(b, r * ga.dir[i]);
    const double fu = std::floor(t.x()), fv = std::floor(t.y());
    const double ax = t.x() - fu, ay = t.y() - fv;
    const int u0 = ((int(fu) % w) + w) % w, u1 = (u0 + 1) % w;
    const int v0 = std::clamp(int(fv), 0, h - 1), v1 = std::clamp(int(fv) + 1, 0, h - 1);
    double wb = 0, wvb = 0;
    const int us[2] = {u0, u1}, vs[2] = {v0, v1};
    const double cu[2] = {1 - ax, ax}, cv[2] = {1 - ay, ay};
    for (int y = 0; y < 2; ++y)
      for (int x = 0; x < 2; ++x) {
        const std::size_t j = std::size_t(vs[y]) * w + us[x];
        const double c = cu[x] * cv[y] * b.weight[j];
        wb += c, wvb += c * b.value[j];
      }
    if (!(wb > 0)) continue;
    const double wt = a.weight[i] * wb * ga.area[i];
    const double va = a.value[i], vb = wvb / wb;
    sw += wt, sa += wt * va, sb += wt * vb, saa += wt * va * va, sbb += wt * vb * vb, sab += wt * va * vb;
  }
  if (overlap) *overlap = ga.sphere > 0 ? sw / ga.sphere : 0;
  if (!(sw > 0)) return -1;
  const double cov = sab - sa * sb / sw, var_a = saa - sa * sa / sw, var_b = sbb - sb * sb / sw;
  if (!(var_a > 0 && var_b > 0)) return -1;
  return cov / std::sqrt(var_a * var_b);
}

double rotation_angle_deg(const Mat3& a, const Mat3& b) {
  return Eigen::AngleAxisd(a * b.transpose()).angle() * 180 / kPi;
}

constexpr double kDistinctDeg = 10;  // rotations closer than this are one answer

Mat3 turn(int axis, double deg) { return Eigen::AngleAxisd(deg * kPi / 180, Vec3::Unit(axis)).toRotationMatrix(); }

}  // namespace

ReflectionPanorama reflection_panorama(const cv::Mat& image, const cv::Mat& flags, const LensModel& lens,
                                       const BallCone& cone, const PanoramaOptions& options) {
  if (image.type() != CV_32FC3 || image.cols != lens.width() || image.rows != lens.height())
    throw std::invalid_argument("reflection panorama: the image must be float RGB of the lens model's size");
  if (!flags.empty() && (flags.type() != CV_8UC1 || flags.size() != image.size()))
    throw std::invalid_argument("reflection panorama: the flags must be 8-bit, one channel, of the image's size");
  if (options.width < 8 || options.width % 2 || options.coarsest < 4 || options.coarsest > options.width ||
      options.supersample < 1)
    throw std::invalid_argument("reflection panorama: invalid sizes");
  BallFeatureOptions fo;
  fo.max_radius_fraction = options.max_radius_fraction;
  fo.camera_mask_deg = options.camera_mask_deg;
  PanoramaLevel fine;
  fine.width = options.width, fine.height = options.width / 2;
  fine.value.assign(std::size_t(fine.width) * fine.height, 0.f);
  fine.weight.assign(fine.value.size(), 0.f);
  std::vector<float> lum(fine.value.size(), 0.f);
  const int s = options.supersample;
  parallel_for_rows(fine.height, [&](int v) {
    for (int u = 0; u < fine.width; ++u) {
      double sum = 0;
      int n = 0;
      for (int j = 0; j < s; ++j)
        for (int i = 0; i < s; ++i) {
          const Vec3 d = panorama_direction(fine, u - 0.5 + (i + 0.5) / s, v - 0.5 + (j + 0.5) / s);
          const auto p = ball_pixel_of(lens, cone, fo, d, false);
          if (!p) continue;
          bool ok = false;
          const float l = luminance_at(image, flags, p->pixel, &ok);
          if (ok) sum += l, ++n;
        }
      const std::size_t k = std::size_t(v) * fine.width + u;
      fine.weight[k] = float(n) / (s * s);
      lum[k] = n ? static_cast<float>(sum / n) : 0.f;
    }
  });
  // log(luminance + eps), eps 1e-3 of the mean seen luminance (noise in black areas is no structure).
  double mean = 0, count = 0;
  for (std::size_t k = 0; k < lum.size(); ++k) mean += fine.weight[k] * lum[k], count += fine.weight[k];
  const double eps = std::max(count > 0 ? 1e-3 * mean / count : 1.0, 1e-30);
  for (std::size_t k = 0; k < lum.size(); ++k)
    fine.value[k] = fine.weight[k] > 0 ? static_cast<float>(std::log(lum[k] + eps)) : 0.f;
  ReflectionPanorama out;
  out.levels.push_back(std::move(fine));
  while (out.levels.back().width / 2 >= options.coarsest) out.levels.push_back(half_size(out.levels.back()));
  return out;
}

double panorama_correlation(const PanoramaLevel& a, const PanoramaLevel& b, const Mat3& b_from_a, double* overlap) {
  return correlate(a, geometry_of(a), b, b_from_a, overlap);
}

RotationSearch search_rotation(const ReflectionPanorama& a, const ReflectionPanorama& b,
                               const RotationSearchOptions& options) {
  if (a.levels.empty() || a.levels.size() != b.levels.size())
    throw std::invalid_argument("rotation search: the panoramas must have the same levels");
  for (std::size_t l = 0; l < a.levels.size(); ++l)
    if (a.levels[l].width != b.levels[l].width || a.levels[l].height != b.levels[l].height)
      throw std::invalid_argument("rotation search: the panoramas must have the same levels");
  if (!(options.grid_deg > 0.5 && options.grid_deg <= 45) || options.candidates < 1)
    throw std::invalid_argument("rotation search: grid step must be in (0.5, 45] degrees, candidates >= 1");
  std::vector<LevelGeometry> geo;
  for (const PanoramaLevel& l : a.levels) geo.push_back(geometry_of(l));
  auto score = [&](std::size_t level, const Mat3& r) {
    double overlap = 0;
    const double z = correlate(a.levels[level], geo[level], b.levels[level], r, &overlap);
    return overlap >= options.min_overlap ? z : -1.0;
  };
  // Coarse grid: where the camera's +z goes (a Fibonacci sphere) x a turn about it.
  const double g = options.grid_deg * kPi / 180;
  const int dirs = static_cast<int>(std::ceil(4 * kPi / (g * g)));
  const int turns = static_cast<int>(std::ceil(2 * kPi / g));
  std::vector<Mat3> grid;
  grid.reserve(std::size_t(dirs) * turns);
  const double golden = kPi * (3 - std::sqrt(5.0));
  for (int i = 0; i < dirs; ++i) {
    const double z = 1 - 2 * (i + 0.5) / dirs, rho = std::sqrt(std::max(0.0, 1 - z * z));
    const Vec3 to(rho * std::cos(golden * i), rho * std::sin(golden * i), z);
    const Mat3 align = Eigen::Quaterniond::FromTwoVectors(Vec3(0, 0, 1), to).toRotationMatrix();
    for (int k = 0; k < turns; ++k) grid.push_back(Eigen::AngleAxisd(k * 2 * kPi / turns, to) * align);
  }
  const std::size_t coarse = a.levels.size() - 1;
  std::vector<double> grid_score(grid.size());
  parallel_for_rows(static_cast<int>(grid.size()),
                    [&](int i) { grid_score[std::size_t(i)] = score(coarse, grid[std::size_t(i)]); });
  std::vector<std::size_t> order(grid.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](std::size_t x, std::size_t y) { return grid_score[x] > grid_score[y]; });
  struct Candidate {
    Mat3 r;
    double s;
  };
  std::vector<Candidate> cands;
  for (std::size_t i : order) {
    if (!(grid_score[i] > -1) || int(cands.size()) >= options.candidates) break;
    bool near = false;
    for (const Candidate& c : cands) near = near || rotation_angle_deg(c.r, grid[i]) < 2 * options.grid_deg;
    if (!near) cands.push_back({grid[i], grid_score[i]});
  }
  RotationSearch out;
  if (cands.empty()) return out;
  // Level by level, finest last: a local search over turns about the camera axes, from the
  // level's texel down to a quarter of it; after the two coarsest levels only the best few go on.
  for (std::size_t level = coarse + 1; level-- > 0;) {
    const double texel_deg = 360.0 / a.levels[level].width;
    parallel_for_rows(static_cast<int>(cands.size()), [&](int ci) {
      Candidate& c = cands[std::size_t(ci)];
      c.s = score(level, c.r);
      for (double step = texel_deg; step >= texel_deg / 4; step /= 2)
        for (int it = 0; it < 30; ++it) {
          Mat3 best = c.r;
          double best_s = c.s;
          for (int axis = 0; axis < 3; ++axis)
            for (double sign : {-1.0, 1.0}) {
              const Mat3 r = turn(axis, sign * step) * c.r;
              const double s = score(level, r);
              if (s > best_s) best_s = s, best = r;
            }
          if (best_s <= c.s) break;
          c.r = best, c.s = best_s;
        }
    });
    std::sort(cands.begin(), cands.end(), [](const Candidate& x, const Candidate& y) { return x.s > y.s; });
    // Candidates that converged onto a better one go; the best few distinct ones go on.
    std::vector<Candidate> distinct;
    for (const Candidate& c : cands) {
      bool near = false;
      for (const Candidate& d : distinct) near = near || rotation_angle_deg(c.r, d.r) < kDistinctDeg;
      if (!near) distinct.push_back(c);
    }
    cands = std::move(distinct);
    if (level + 1 <= coarse && cands.size() > 6) cands.resize(6);
  }
  out.b_from_a = cands.front().r;
  out.score = cands.front().s;
  correlate(a.levels.front(), geo.front(), b.levels.front(), out.b_from_a, &out.overlap);
  for (std::size_t i = 1; i < cands.size(); ++i) {
    const double deg = rotation_angle_deg(cands[i].r, out.b_from_a);
    if (deg > kDistinctDeg && cands[i].s > out.runner_up) out.runner_up = cands[i].s, out.runner_up_deg = deg;
  }
  return out;
}

}  // namespace rsibr
