#include "calib/orientation/stand_line.h"
#include "core/luminance.h"

#include <Eigen/Dense>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <vector>

namespace rsibr {

namespace {

struct LogImage {
  cv::Mat l;  // CV_32FC1, ln(luminance + eps)
  bool inside(const Vec2& p) const { return p.x() >= 0 && p.y() >= 0 && p.x() <= l.cols - 1 && p.y() <= l.rows - 1; }
  double at(const Vec2& p) const {
    const int x0 = std::clamp(int(std::floor(p.x())), 0, l.cols - 2),
              y0 = std::clamp(int(std::floor(p.y())), 0, l.rows - 2);
    const double fx = p.x() - x0, fy = p.y() - y0;
    const float* r0 = l.ptr<float>(y0);
    const float* r1 = l.ptr<float>(y0 + 1);
    return (1 - fy) * ((1 - fx) * r0[x0] + fx * r0[x0 + 1]) + fy * ((1 - fx) * r1[x0] + fx * r1[x0 + 1]);
  }
};

struct Score {
  double score = 0, coverage = 0;
};

// The pole hypothesis (direction phi, half width h) scored over t in [t0, t1] (see the header).
Score score_of(const LogImage& img, const Vec2& c, double phi, double h, double t0, double t1, double min_edge) {
  const Vec2 d(std::sin(phi), std::cos(phi)), n(std::cos(phi), -std::sin(phi));
  double sum = 0;
  int valid = 0, good = 0;
  for (double t = t0; t <= t1; t += 1.0) {
    const Vec2 a = c + t * d + h * n, b = c + t * d - h * n;
    if (!img.inside(a + 1.5 * n) || !img.inside(b - 1.5 * n)) continue;
    const double ga = img.at(a + n) - img.at(a - n), gb = img.at(b + n) - img.at(b - n);
    ++valid;
    if (ga * gb < 0) {
      const double s = std::min(std::abs(ga), std::abs(gb));
      sum += s;
      good += s > min_edge;
    }
  }
  if (valid < 20) return {};
  return {sum / valid, double(good) / valid};
}

// The edge across the line nearest offset w0 (within +-3 px): sub-pixel position of the largest
// |gradient| along n, by a parabola; NaN when none.
double edge_offset(const LogImage& img, const Vec2& q, const Vec2& n, double w0) {
  double best = 0, best_w = NAN;
  std::vector<double> g;
  for (int k = -12; k <= 12; ++k) {
    const double w = w0 + 0.25 * k;
    const Vec2 p = q + w * n;
    if (!img.inside(p + n) || !img.inside(p - n)) return NAN;
    g.push_back(std::abs(img.at(p + n) - img.at(p - n)));
  }
  for (std::size_t i = 1; i + 1 < g.size(); ++i)
    if (g[i] > best && g[i] >= g[i - 1] && g[i] >= g[i + 1]) {
      const double den = g[i - 1] - 2 * g[i] + g[i + 1];
      const double f = den < 0 ? 0.5 * (g[i - 1] - g[i + 1]) / den : 0.0;
      best = g[i], best_w = w0 + 0.25 * (double(i) - 12 + f);
    }
  return best_w;
}

}  // namespace

std::optional<StandLine> find_stand_line(const cv::Mat& image, const LensModel& lens, const BallCone& ball,
                                         const StandLineOptions& o) {
  if (image.type() != CV_32FC3 || image.cols != lens.width() || image.rows != lens.height()) return std::nullopt;
  LogImage img;
  cv::Mat lum;
  const auto& w = luma_coefficients();
  cv::transform(image, lum, cv::Matx13f(float(w[0]), float(w[1]), float(w[2])));
  cv::max(lum, 0.0, lum);
  cv::patchNaNs(lum, 0.0);
  const double eps = std::max(1e-3 * cv::mean(lum)[0], 1e-30);
  cv::log(lum + eps, img.l);
  const Vec2 c = lens.project(ball.axis);
  double radius = 0;
  for (const Vec2& q : cone_outline(ball, lens, 32)) radius += (q - c).norm() / 32;
  if (!c.allFinite() || !(radius > 3)) return std::nullopt;
  const double t0 = 1.25 * radius, t1 = 4 * radius;
  // Search over the direction and the half width.
  double best = 0, best_phi = 0, best_h = 0, best_cov = 0;
  std::vector<double> phis;
  for (double a = -o.max_angle_deg; a <= o.max_angle_deg + 1e-9; a += 0.25) phis.push_back(a * kDeg);
  std::vector<double> best_at_phi(phis.size(), 0.0);
  for (std::size_t i = 0; i < phis.size(); ++i)
    for (double f = 0.1; f <= 0.7 + 1e-9; f += 0.05) {
      const Score s = score_of(img, c, phis[i], f * radius, t0, t1, 0.5 * o.min_contrast);
      best_at_phi[i] = std::max(best_at_phi[i], s.score);
      if (s.score > best) best = s.score, best_phi = phis[i], best_h = f * radius, best_cov = s.coverage;
    }
  if (!(best >= o.min_contrast) || best_cov < o.min_coverage) return std::nullopt;
  // Distinct from other directions (beyond 3 pole widths at mid length).
  const double away = std::max(3 * std::atan(2 * best_h / (0.5 * (t0 + t1))), 4 * kDeg);
  double second = 1e-6;
  for (std::size_t i = 0; i < phis.size(); ++i)
    if (std::abs(phis[i] - best_phi) > away) second = std::max(second, best_at_phi[i]);
  const double distinction = best / second;
  if (distinction < o.min_distinction) return std::nullopt;
  // The pole's midline from its two edges at every t, as camera rays; the plane through the camera
  // centre that fits them best (the smallest eigenvector of sum r r^T).
  const Vec2 d(std::sin(best_phi), std::cos(best_phi)), n(std::cos(best_phi), -std::sin(best_phi));
  std::vector<Vec3> rays;
  for (double t = t0; t <= t1; t += 1.0) {
    const Vec2 q = c + t * d;
    const double a = edge_offset(img, q, n, best_h), b = edge_offset(img, q, n, -best_h);
    if (!std::isfinite(a) || !std::isfinite(b) || !(a - b > 0.5 * best_h)) continue;
    const Vec3 r = lens.unproject(q + 0.5 * (a + b) * n);
    if (r.allFinite() && r.norm() > 0) rays.push_back(r.normalized());
  }
  if (rays.size() < 20) return std::nullopt;
  Mat3 s = Mat3::Zero();
  for (const Vec3& r : rays) s += r * r.transpose();
  Eigen::SelfAdjointEigenSolver<Mat3> eig(s);
  Vec3 m = eig.eigenvectors().col(0);
  // Robust pass: rays off the plane by more than 3 robust sigmas (a knot, a label on the pole) out.
  std::vector<double> res;
  for (const Vec3& r : rays) res.push_back(std::abs(r.dot(m)));
  std::vector<double> sorted = res;
  std::nth_element(sorted.begin(), sorted.begin() + long(sorted.size() / 2), sorted.end());
  const double mad = std::max(1.4826 * sorted[sorted.size() / 2], 1e-9);
  s.setZero();
  int kept = 0;
  double sum2 = 0;
  for (std::size_t i = 0; i < rays.size(); ++i)
    if (res[i] < 3 * mad) s += rays[i] * rays[i].transpose(), ++kept;
  if (kept < 20) return std::nullopt;
  eig.compute(s);
  m = eig.eigenvectors().col(0);
  for (const Vec3& r : rays)
    if (std::abs(r.dot(m)) < 3 * mad) sum2 += r.dot(m) * r.dot(m);
  // The normal's std dev toward the plane's weaker in-plane axis: residual / sqrt(its eigenvalue).
  const double sigma_res2 = sum2 / std::max(1, kept - 2);
  StandLine out;
  out.plane_normal = m.normalized();
  out.angle_deg = best_phi / kDeg;
  out.half_width_px = best_h;
  out.score = best;
  out.coverage = best_cov;
  out.distinction = distinction;
  out.sigma_deg = std::max(0.1, std::sqrt(sigma_res2 / std::max(eig.eigenvalues()(1), 1e-12)) / kDeg);
  return out;
}

}  // namespace rsibr
