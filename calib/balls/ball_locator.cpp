#include "calib/balls/ball_locator.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <tuple>

namespace rsibr {

namespace {

// Equal-weight channel mean (edges of any colour count alike), negative and NaN as 0.
cv::Mat brightness_image(const cv::Mat& image) {
  cv::Mat lum;
  if (image.type() == CV_32FC3) {
    cv::transform(image, lum, cv::Matx13f(1.f / 3, 1.f / 3, 1.f / 3));
  } else if (image.type() == CV_32FC1) {
    lum = image.clone();
  } else {
    throw std::invalid_argument("ball image: expected a float (CV_32FC3 or CV_32FC1) linear image");
  }
  cv::max(lum, 0.0, lum);
  cv::patchNaNs(lum, 0.0);
  return lum;
}

// Bilinear sample with pixel centres at integers; the caller keeps p inside [0, w-1] x [0, h-1].
double sample(const cv::Mat& img, double x, double y) {
  const int x0 = std::clamp(static_cast<int>(std::floor(x)), 0, img.cols - 2);
  const int y0 = std::clamp(static_cast<int>(std::floor(y)), 0, img.rows - 2);
  const double fx = x - x0, fy = y - y0;
  const float* r0 = img.ptr<float>(y0);
  const float* r1 = img.ptr<float>(y0 + 1);
  return (1 - fy) * ((1 - fx) * r0[x0] + fx * r0[x0 + 1]) + fy * ((1 - fx) * r1[x0] + fx * r1[x0 + 1]);
}

constexpr double kStep = 0.25;  // samples per pixel along a search line: 4

// Edges on the line q + t n, t in [t0, t1] (see the header), strongest first, at most
// `max_edges`, local maxima of the log gradient at least 2 px apart; empty when the line leaves
// the image or has no edge of the required contrast.
struct Edge {
  Vec2 px;
  double t;         // position on the line
  double contrast;  // log gradient over 2 px
};

std::vector<Edge> find_edges(const cv::Mat& lum, double eps, const Vec2& q, const Vec2& n, double t0, double t1,
                             double min_log_contrast, int max_edges) {
  const double pad = 2.0;  // the level samples reach 1.5 px (2 px for the log gradient) beyond
  const int m = static_cast<int>(std::ceil((t1 - t0 + 2 * pad) / kStep)) + 1;
  std::vector<double> p(m), lp(m);
  for (int i = 0; i < m; ++i) {
    const Vec2 x = q + (t0 - pad + i * kStep) * n;
    if (!(x.x() >= 0 && x.y() >= 0 && x.x() <= lum.cols - 1 && x.y() <= lum.rows - 1)) return {};
    p[i] = sample(lum, x.x(), x.y());
    lp[i] = std::log(p[i] + eps);
  }
  const int k1 = static_cast<int>(std::lround(1.0 / kStep));  // 1 px in samples
  const int first = static_cast<int>(std::lround(pad / kStep)), last = m - 1 - first;
  std::vector<double> g(m, 0.0);
  for (int i = first; i <= last; ++i) g[i] = std::abs(lp[i + k1] - lp[i - k1]);
  std::vector<int> peaks;
  for (int i = first; i <= last; ++i)
    if (g[i] >= min_log_contrast && (i == first || g[i] >= g[i - 1]) && (i == last || g[i] > g[i + 1]))
      peaks.push_back(i);
  std::sort(peaks.begin(), peaks.end(), [&](int a, int b) { return g[a] > g[b] || (g[a] == g[b] && a < b); });
  std::vector<int> kept;
  for (int i : peaks) {
    bool near = false;
    for (int k : kept) near |= std::abs(k - i) < 2 * k1;
    if (!near) kept.push_back(i);
    if (static_cast<int>(kept.size()) == max_edges) break;
  }
  const int k15 = static_cast<int>(std::lround(1.5 / kStep));
  std::vector<Edge> out;
  for (int best : kept) {
    const double in = p[best - k15], out_level = p[best + k15], mid = 0.5 * (in + out_level);
    // The crossing of the mid level nearest the gradient peak.
    double t_best = 0, d_best = 1e300;
    for (int i = best - k15; i < best + k15; ++i) {
      const double a = p[i] - mid, b = p[i + 1] - mid;
      if ((a <= 0 && b > 0) || (a >= 0 && b < 0)) {
        const double f = a / (a - b);
        const double d = std::abs(i + f - best);
        if (d < d_best) d_best = d, t_best = t0 - pad + (i + f) * kStep;
      }
    }
    if (d_best < 1e300) out.push_back({q + t_best * n, t_best, g[best]});
  }
  return out;
}

// The part [t0', t1'] of [t0, t1] where q + t n lies at least `margin` px inside the image (the
// pixel-centre box [0, w-1] x [0, h-1]); t1' < t0' when none does.
std::pair<double, double> inside_part(const cv::Mat& img, const Vec2& q, const Vec2& n, double t0, double t1,
                                      double margin) {
  const double lo[2] = {margin, margin}, hi[2] = {img.cols - 1 - margin, img.rows - 1 - margin};
  for (int a = 0; a < 2; ++a) {
    if (std::abs(n[a]) < 1e-12) {
      if (q[a] < lo[a] || q[a] > hi[a]) return {1, 0};
      continue;
    }
    double u = (lo[a] - q[a]) / n[a], v = (hi[a] - q[a]) / n[a];
    if (u > v) std::swap(u, v);
    t0 = std::max(t0, u), t1 = std::min(t1, v);
  }
  return {t0, t1};
}

std::string where(const BallGuess& g) {
  std::ostringstream s;
  s.precision(1);
  s << std::fixed << "ball at (" << g.centre_px.x() << ", " << g.centre_px.y() << ")";
  return s.str();
}

}  // namespace

BallLocation locate_ball(const cv::Mat& image, const LensModel& lens, const BallGuess& guess,
                         const BallLocateOptions& options) {
  if (image.cols != lens.width() || image.rows != lens.height())
    throw std::invalid_argument(where(guess) + ": the image is " + std::to_string(image.cols) + "x" +
                                std::to_string(image.rows) + ", the lens model " + std::to_string(lens.width()) + "x" +
                                std::to_string(lens.height()));
  if (!(guess.radius_px > 1) || !guess.centre_px.allFinite())
    throw std::invalid_argument(where(guess) + ": the guessed radius must be > 1 px");
  const cv::Mat lum = brightness_image(image);
  // eps of the log: 1e-3 of the mean level, so noise in black areas makes no edges.
  const double eps = std::max(1e-3 * cv::mean(lum)[0], 1e-30);
  const int lines = options.lines > 0 ? options.lines : std::max(48, static_cast<int>(2 * kPi * guess.radius_px / 1.5));

  // Pass 1: radial lines from the guessed centre, up to 3 edge candidates each (RANSAC finds the
  // ones on one cone among reflections, the stand and the background); a line that leaves the
  // image is skipped, or with clip_lines searched over its part inside.
  std::vector<Vec3> rays;
  const double band = std::max(4.0, options.search_fraction * guess.radius_px);
  for (int k = 0; k < lines; ++k) {
    const double phi = 2 * kPi * (k + 0.5) / lines;
    const Vec2 n(std::cos(phi), std::sin(phi));
    double t0 = guess.radius_px - band, t1 = guess.radius_px + band;
    if (options.clip_lines) {
      std::tie(t0, t1) = inside_part(lum, guess.centre_px, n, t0, t1, 2.5);
      if (!(t1 - t0 >= 4)) continue;
    }
    for (const Edge& e : find_edges(lum, eps, guess.centre_px, n, t0, t1, options.min_log_contrast, 3))
      rays.push_back(lens.unproject(e.px));
  }
  if (rays.size() < 8)
    throw std::invalid_argument(where(guess) + ": only " + std::to_string(rays.size()) +
                                " outline points found (no ball there, or no contrast at its outline)");
  ConeFit fit;
  try {
    fit = fit_cone(rays, lens, options.fit);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(where(guess) + ": " + e.what());
  }

  // Pass 2 (twice): lines normal to the fitted outline, +- refine_px.
  BallLocation loc;
  for (int pass = 0; pass < 2; ++pass) {
    const std::vector<Vec2> outline = cone_outline(fit.cone, lens, 2 * lines);
    rays.clear();
    loc.outline_px.clear();
    const Vec2 c = lens.project(fit.cone.axis);
    for (int k = 0; k < lines; ++k) {
      const Vec2& q = outline[2 * k + 1];
      const Vec2 tangent = outline[(2 * k + 2) % (2 * lines)] - outline[2 * k];
      Vec2 n(tangent.y(), -tangent.x());
      if (!(n.norm() > 0)) continue;
      n.normalize();
      if (n.dot(q - c) < 0) n = -n;  // outward
      if (pass == 1) {
        const auto [t0, t1] = inside_part(lum, q, n, -options.refine_px, options.refine_px, 2.0);
        loc.lines_inside += t0 <= -options.refine_px && t1 >= options.refine_px;
      }
      // Of the edges at least 0.3 times as strong as the strongest, the one nearest the fitted
      // outline (a reflection's edge just inside a chrome ball's rim can be the stronger one).
      const auto edges = find_edges(lum, eps, q, n, -options.refine_px, options.refine_px, options.min_log_contrast, 3);
      if (edges.empty()) continue;
      const Edge* pick = &edges.front();
      for (const Edge& e : edges)
        if (e.contrast >= 0.3 * edges.front().contrast && std::abs(e.t) < std::abs(pick->t)) pick = &e;
      loc.outline_px.push_back(pick->px);
      rays.push_back(lens.unproject(pick->px));
    }
    if (rays.size() < 8)
      throw std::invalid_argument(where(guess) + ": only " + std::to_string(rays.size()) +
                                  " outline points found on the refined outline");
    ConeFitOptions refine = options.fit;
    refine.ransac_iterations = 0;  // the start is good now; outliers go by the Huber loss
    refine.seed = options.fit.seed;
    try {
      ConeFit f2 = fit_cone(rays, lens, refine);
      fit = f2;
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(where(guess) + ": " + e.what());
    }
  }
  loc.fit = fit;
  const ConeCircle circle = cone_circle(fit.cone, lens);
  loc.centre_px = circle.centre_px;
  loc.radius_px = circle.radius_px;
  return loc;
}

double BallLocation::outline_support(double tol_px) const {
  int in = 0;
  for (double r : fit.residual_px) in += std::abs(r) < tol_px;
  return lines_inside > 0 ? double(in) / double(lines_inside) : 0.0;
}

std::vector<BallGuess> detect_balls(const cv::Mat& image, double min_radius_px, double max_radius_px, int max_count,
                                    int per_band) {
  const cv::Mat lum = brightness_image(image);
  // Tone map: log luminance stretched between its 1st and 99th percentiles to 8 bits.
  cv::Mat lg;
  const double eps = std::max(1e-3 * cv::mean(lum)[0], 1e-30);
  cv::log(lum + eps, lg);
  // The two order statistics by selection (linear; a full sort was 5% of the balls step).
  std::vector<float> v(lg.begin<float>(), lg.end<float>());
  const auto lo_at = v.begin() + std::ptrdiff_t(v.size() / 100),
             hi_at = v.begin() + std::ptrdiff_t(v.size() * 99 / 100);
  std::nth_element(v.begin(), hi_at, v.end());
  std::nth_element(v.begin(), lo_at, hi_at);
  const double lo = *lo_at, hi = *hi_at;
  cv::Mat u8;
  lg.convertTo(u8, CV_8U, 255.0 / std::max(hi - lo, 1e-6), -lo * 255.0 / std::max(hi - lo, 1e-6));
  cv::GaussianBlur(u8, u8, cv::Size(5, 5), 1.2);
  std::vector<std::pair<double, double>> bands;
  if (per_band > 0) {
    for (double r0 = min_radius_px; r0 < max_radius_px; r0 *= 2)
      bands.push_back({r0, std::min(2.1 * r0, max_radius_px)});
  } else {
    bands.push_back({min_radius_px, max_radius_px});
  }
  std::vector<BallGuess> out;
  for (const auto& [r0, r1] : bands) {
    std::vector<cv::Vec3f> circles;
    cv::HoughCircles(u8, circles, cv::HOUGH_GRADIENT, 1.0, std::max(2.0 * r0, 4.0), 100, 20,
                     static_cast<int>(std::floor(r0)), static_cast<int>(std::ceil(r1)));
    int kept = 0;
    for (const auto& c : circles) {
      if (static_cast<int>(out.size()) >= max_count || (per_band > 0 && kept >= per_band)) break;
      out.push_back({Vec2(c[0], c[1]), c[2]});
      ++kept;
    }
  }
  return out;
}

}  // namespace rsibr
