#include "calib/balls/ball_identification.h"

#include "calib/lens/far_camera.h"
#include "core/luminance.h"

#include <Eigen/Dense>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <optional>
#include <sstream>

namespace rsibr {

namespace {

double lum_of(const cv::Vec3f& p) { return std::max(0.0, luminance(p)); }

std::string px_text(const Vec2& p, double r) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(1);
  s << "(" << p.x() << ", " << p.y() << ", r " << r << ")";
  return s.str();
}

struct Disc {
  Vec2 c;
  double r;
};

// Pixels (x, y) with centres within `fraction` radii of the ball centre, inside the image and
// outside the discs `ex` (other balls overlapping this one).
template <class F>
void for_disc(const cv::Mat& image, const Vec2& c, double r, double fraction, const std::vector<Disc>& ex, F&& f) {
  const double rr = fraction * r;
  const int x0 = std::max(0, int(std::floor(c.x() - rr))), x1 = std::min(image.cols - 1, int(std::ceil(c.x() + rr)));
  const int y0 = std::max(0, int(std::floor(c.y() - rr))), y1 = std::min(image.rows - 1, int(std::ceil(c.y() + rr)));
  for (int y = y0; y <= y1; ++y)
    for (int x = x0; x <= x1; ++x) {
      if ((Vec2(x, y) - c).norm() > rr) continue;
      bool hidden = false;
      for (const Disc& d : ex) hidden |= (Vec2(x, y) - d.c).norm() <= d.r + std::max(2.0, 0.05 * d.r);  // its limb too
      if (!hidden) f(x, y);
    }
}

// ln(max(1e-6, L)) over a disc's box (within `reach` px of the centre, clipped to the image), made
// once per measurement: the texture measures read each pixel's log several times.
struct LogLum {
  int x0 = 0, y0 = 0;
  cv::Mat ln;  // CV_64FC1
  LogLum(const cv::Mat& image, const Vec2& c, double reach) {
    x0 = std::max(0, int(std::floor(c.x() - reach)));
    y0 = std::max(0, int(std::floor(c.y() - reach)));
    const int x1 = std::min(image.cols - 1, int(std::ceil(c.x() + reach)));
    const int y1 = std::min(image.rows - 1, int(std::ceil(c.y() + reach)));
    ln = cv::Mat(std::max(0, y1 - y0 + 1), std::max(0, x1 - x0 + 1), CV_64FC1);
    for (int y = 0; y < ln.rows; ++y) {
      double* row = ln.ptr<double>(y);
      const cv::Vec3f* in = image.ptr<cv::Vec3f>(y0 + y) + x0;
      for (int x = 0; x < ln.cols; ++x) row[x] = std::log(std::max(1e-6, lum_of(in[x])));
    }
  }
  // The caller keeps (x, y) inside the box.
  double operator()(int x, int y) const { return ln.at<double>(y - y0, x - x0); }
};

// Mean |ln L| change between neighbouring pixels inside 0.8 radii: a chrome ball reflects the whole
// world, edges compressed toward its rim; a grey ball's shading may span as many stops (sun and
// shadow) but changes slowly, so the pixel-to-pixel change, not the spread, tells them apart.
double disc_texture(const cv::Mat& image, const LogLum& l, const Vec2& c, double r, const std::vector<Disc>& ex) {
  double s = 0;
  long n = 0;
  for_disc(image, c, r, 0.8, ex, [&](int x, int y) {
    if (x + 1 >= image.cols || y + 1 >= image.rows) return;
    const double v = l(x, y);
    s += std::abs(l(x + 1, y) - v) + std::abs(l(x, y + 1) - v);
    n += 2;
  });
  return n > 0 ? s / double(n) : 0;
}

// A mirror shows the world compressed toward its rim: nearly every pixel between half and 0.9 of
// the radius differs from a neighbour. A disc that merely holds a ball (a ringed target behind the
// rig) has edges there only at its rings. The neighbour is r / 64 pixels away (at least 1), so the
// measure does not depend on the ball's size in pixels: a ball photographed 3x larger shows the
// same world over 3x the pixels, and its neighbours one pixel apart differ 3x less (a 189 px chrome
// ball in a 13 MP phone frame measured 0.23, under the chrome test's 0.25, at one pixel).
double disc_rim_texture(const cv::Mat& image, const LogLum& l, const Vec2& c, double r, const std::vector<Disc>& ex) {
  long n = 0, textured = 0;
  const int d = std::max(1, int(std::lround(r / 64)));
  for_disc(image, c, r, 0.9, ex, [&](int x, int y) {
    if ((Vec2(x, y) - c).norm() < 0.5 * r || x + d >= image.cols || y + d >= image.rows) return;
    const double v = l(x, y);
    const double dx = std::abs(l(x + d, y) - v);
    const double dy = std::abs(l(x, y + d) - v);
    ++n;
    textured += std::max(dx, dy) > 0.06;
  });
  return n >= 20 ? double(textured) / double(n) : 0;
}

// A mirror compresses the world radially toward its rim: what lies in a thin band of directions
// there is drawn as a thin band along the rim, so the edges run along it and the log-luminance
// gradient points across it (radially). At a distance rho (in radii) from the centre a mirror
// stretches directions radially 2 / sqrt(1 - rho^2) and tangentially sin(2 asin rho) / rho: 2x more
// radially at 0.7, 5x at 0.9, 10x at 0.95. Returned: sum (g_r^2 - g_t^2) / |g| over sum |g| for the
// pixels between 0.8 and 0.96 radii, stopping 2 px plus the step short of the outline (whose own
// edge is radial for any disc) and at least 4 px wide (a small ball), in [-1, 1]: about 0 for a
// patch of the scene, which has no reason to line up with a circle drawn over it, and clearly
// positive for a mirror ball. The neighbour step is r / 64 as for the rim texture.
double disc_rim_radial(const cv::Mat& image, const LogLum& l, const Vec2& c, double r, const std::vector<Disc>& ex) {
  const int d = std::max(1, int(std::lround(r / 64)));
  const double outer = std::min(0.96 * r, r - 2.0 - d), inner = std::min(0.8 * r, outer - 4.0);
  double along = 0, total = 0;
  for_disc(image, c, r, 0.96, ex, [&](int x, int y) {
    const Vec2 u = Vec2(x, y) - c;
    const double dist = u.norm();
    if (dist < inner || dist > outer || x < d || y < d || x + d >= image.cols || y + d >= image.rows) return;
    const double gx = l(x + d, y) - l(x - d, y), gy = l(x, y + d) - l(x, y - d);
    const double g = std::hypot(gx, gy);
    if (!(g > 1e-9)) return;
    const double gr = (gx * u.x() + gy * u.y()) / dist, gt = (gy * u.x() - gx * u.y()) / dist;
    along += (gr * gr - gt * gt) / g;
    total += g;
  });
  return total > 0 ? along / total : 0;
}

// The 98th percentile, over the pixels within 0.9 radii, of |grad log2(L + eps)| in stops per ball
// radius (central differences; eps = 1e-3 of the disc's mean): a grey ball scores a few stops, a
// mirror tens (the environment's edges compressed toward its rim).
double disc_mirror_score(const cv::Mat& image, const Vec2& c, double r, const std::vector<Disc>& ex) {
  double mean = 0;
  long count = 0;
  for_disc(image, c, r, 0.9, ex, [&](int x, int y) { mean += lum_of(image.at<cv::Vec3f>(y, x)), ++count; });
  if (count < 20 || !(mean > 0)) return 0;
  const double eps = 1e-3 * mean / double(count);
  std::vector<double> grads;
  auto l = [&](int x, int y) { return std::log2(lum_of(image.at<cv::Vec3f>(y, x)) + eps); };
  for_disc(image, c, r, 0.9, ex, [&](int x, int y) {
    if (x < 1 || y < 1 || x + 1 >= image.cols || y + 1 >= image.rows) return;
    const double gx = 0.5 * (l(x + 1, y) - l(x - 1, y)), gy = 0.5 * (l(x, y + 1) - l(x, y - 1));
    grads.push_back(std::hypot(gx, gy) * r);
  });
  if (grads.empty()) return 0;
  const auto q = grads.begin() + long(0.98 * double(grads.size() - 1));
  std::nth_element(grads.begin(), q, grads.end());
  return *q;
}

// A Lambertian ball's radiance is albedo E(n) / pi, and E is smooth: spherical harmonics of order
// 2 (9 terms) hold all but a few percent of the irradiance of an extended sky, but not the kink a
// sun leaves at its terminator (a clamped cosine's energy above order 2 reaches 10-30% of a
// mostly shadowed disc's mean). So the model is the 9 terms plus k max(0, n . l) for the best of
// directions l (k >= 0 is not imposed: a kink the wrong way fits worse):
//
//   L(n) ~ sum_j c_j Y_j(n) + k max(0, n . l)
//
// fitted by least squares over the pixels within 0.9 radii (the exact surface normal: the pixel's
// ray meets the sphere of radius 1 about C = axis / sin(alpha)), by normal equations per l (the
// 9 x 9 part shared) and once more, exactly, for the best l. Returned: the RMS residual over the
// mean, and the mean |change of ln(L / fit)| between neighbouring pixels within 0.8 radii (the
// texture smooth shading does not explain).
struct LambertFit {
  double residual = std::numeric_limits<double>::infinity();
  double unexplained_texture = std::numeric_limits<double>::infinity();
};

LambertFit lambert_fit(const cv::Mat& image, const LensModel& lens, const BallLocation& loc,
                       const std::vector<Disc>& ex) {
  const Vec3 centre = loc.fit.cone.axis.normalized() / std::sin(loc.fit.cone.half_angle);
  struct Px {
    int x, y;
    Vec3 n;
    double v;
  };
  std::vector<Px> px;
  // The disc's rays from a table over its box (every 4 px, cubic: ~1e-4 px), not one iterative
  // unprojection per pixel; exactly where the table cannot be made (a ray behind the camera).
  std::optional<RayTable> table;
  try {
    const Vec2 half = Vec2::Constant(0.9 * loc.radius_px + 2);
    table.emplace(lens, 4, loc.centre_px - half, loc.centre_px + half);
  } catch (const std::invalid_argument&) {
  }
  for_disc(image, loc.centre_px, loc.radius_px, 0.9, ex, [&](int x, int y) {
    const Vec3 d = table ? table->direction(x, y) : lens.unproject(Vec2(x, y)).normalized();
    const double b = d.dot(centre), disc = b * b - (centre.squaredNorm() - 1);
    if (!(disc > 0)) return;
    px.push_back({x, y, (b - std::sqrt(disc)) * d - centre, lum_of(image.at<cv::Vec3f>(y, x))});
  });
  LambertFit out;
  if (px.size() < 30) return out;
  auto sh = [](const Vec3& n) {
    return Eigen::Matrix<double, 9, 1>(1, n.x(), n.y(), n.z(), n.x() * n.y(), n.x() * n.z(), n.y() * n.z(),
                                       n.x() * n.x() - n.y() * n.y(), 3 * n.z() * n.z() - 1);
  };
  // The direction search on at most 4096 pixels (a stride); the final fit on all.
  const std::size_t stride = std::max<std::size_t>(1, px.size() / 4096);
  Eigen::Matrix<double, 9, 9> g = Eigen::Matrix<double, 9, 9>::Zero();
  Eigen::Matrix<double, 9, 1> gv = Eigen::Matrix<double, 9, 1>::Zero();
  double mean = 0;
  for (const Px& p : px) mean += p.v;
  mean /= double(px.size());
  if (!(mean > 0)) return out;
  // The sample's normals, basis rows and values (over the mean), made once for every l tried.
  std::vector<Vec3> sn;
  std::vector<Eigen::Matrix<double, 9, 1>> sy;
  std::vector<double> sv;
  double vv = 0;
  for (std::size_t i = 0; i < px.size(); i += stride) {
    const auto y = sh(px[i].n);
    const double v = px[i].v / mean;
    g += y * y.transpose(), gv += y * v;
    sn.push_back(px[i].n), sy.push_back(y), sv.push_back(v);
    vv += v * v;
  }
  // Sum of squared residuals (in units of the mean) with the sun term along l.
  auto sse_along = [&](const Vec3& l) {
    Eigen::Matrix<double, 10, 10> a = Eigen::Matrix<double, 10, 10>::Zero();
    Eigen::Matrix<double, 10, 1> rhs = Eigen::Matrix<double, 10, 1>::Zero();
    a.topLeftCorner<9, 9>() = g;
    rhs.head<9>() = gv;
    Eigen::Matrix<double, 9, 1> cross = Eigen::Matrix<double, 9, 1>::Zero();
    double cc = 0, cv = 0;
    for (std::size_t i = 0; i < sn.size(); ++i) {
      const double c = sn[i].dot(l);
      if (c > 0) cross += sy[i] * c, cc += c * c, cv += c * sv[i];
    }
    a.block<9, 1>(0, 9) = cross;
    a(9, 9) = cc;
    rhs[9] = cv;
    a.block<1, 9>(9, 0) = a.block<9, 1>(0, 9).transpose();
    if (!(a(9, 9) > 1e-9)) return std::numeric_limits<double>::infinity();
    const Eigen::Matrix<double, 10, 1> x = a.ldlt().solve(rhs);
    const double sse = vv - 2 * x.dot(rhs) + x.dot(a * x);
    return std::isfinite(sse) ? sse : std::numeric_limits<double>::infinity();
  };
  // 256 directions (a Fibonacci sphere, about 13 degrees apart), then the best refined by a
  // pattern search down to 0.4 degrees: a sun behind the ball lights a crescent a coarse l misses.
  const int kDirections = 256;
  double best = std::numeric_limits<double>::infinity();
  Vec3 best_l = Vec3::UnitZ();
  for (int k = 0; k < kDirections; ++k) {
    const double z = 1 - (2 * k + 1.0) / kDirections, r = std::sqrt(std::max(0.0, 1 - z * z));
    const double phi = k * 2.399963229728653;  // the golden angle
    const Vec3 l(r * std::cos(phi), r * std::sin(phi), z);
    const double e = sse_along(l);
    if (e < best) best = e, best_l = l;
  }
  for (double step = 0.12; step > 0.007; step *= 0.5) {
    const Vec3 u = best_l.unitOrthogonal(), v = best_l.cross(u);
    bool moved = true;
    while (moved) {
      moved = false;
      for (const Vec3& d : std::array<Vec3, 4>{u, Vec3(-u), v, Vec3(-v)}) {
        const Vec3 l = (best_l + step * d).normalized();
        const double e = sse_along(l);
        if (e < best) best = e, best_l = l, moved = true;
      }
    }
  }
  // The final fit on every pixel, by its 10 x 10 normal equations in units of the mean (the basis
  // is well conditioned over a visible hemisphere; a column-pivoting QR of the pixels x 10 matrix
  // gave the same residual and cost a quarter of the candidates' measurement).
  auto row = [&](const Px& p) {
    Eigen::Matrix<double, 10, 1> r;
    r.head<9>() = sh(p.n);
    r[9] = std::max(0.0, p.n.dot(best_l));
    return r;
  };
  Eigen::Matrix<double, 10, 10> ata = Eigen::Matrix<double, 10, 10>::Zero();
  Eigen::Matrix<double, 10, 1> atv = Eigen::Matrix<double, 10, 1>::Zero();
  for (const Px& p : px) {
    const Eigen::Matrix<double, 10, 1> r = row(p);
    ata.selfadjointView<Eigen::Lower>().rankUpdate(r);
    atv += r * (p.v / mean);
  }
  ata = ata.selfadjointView<Eigen::Lower>();
  const Eigen::Matrix<double, 10, 1> x = ata.ldlt().solve(atv) * mean;
  Eigen::VectorXd fit(int(px.size()));
  double sq = 0;
  for (std::size_t i = 0; i < px.size(); ++i) {
    fit[int(i)] = row(px[i]).dot(x);
    sq += (fit[int(i)] - px[i].v) * (fit[int(i)] - px[i].v);
  }
  out.residual = std::sqrt(sq / double(px.size())) / mean;
  // ln(L / fit) on the pixels within 0.8 radii (the fit floored at 1e-3 of the mean: a shadow),
  // averaged over 3 x 3 neighbours (pixel noise, 2-6% in a merged HDR, is not texture; a mirror's
  // reflected edges survive the average), then its change between neighbours.
  const double rr = 0.8 * loc.radius_px;
  const int x0 = std::max(0, int(loc.centre_px.x() - rr) - 1), y0 = std::max(0, int(loc.centre_px.y() - rr) - 1);
  const int x1 = std::min(image.cols, int(loc.centre_px.x() + rr) + 2),
            y1 = std::min(image.rows, int(loc.centre_px.y() + rr) + 2);
  if (x1 - x0 < 3 || y1 - y0 < 3) return out;
  cv::Mat q(y1 - y0, x1 - x0, CV_64F, cv::Scalar(0)), w(y1 - y0, x1 - x0, CV_64F, cv::Scalar(0));
  for (std::size_t i = 0; i < px.size(); ++i)
    if ((Vec2(px[i].x, px[i].y) - loc.centre_px).norm() <= rr && px[i].x >= x0 && px[i].x < x1 && px[i].y >= y0 &&
        px[i].y < y1) {
      q.at<double>(px[i].y - y0, px[i].x - x0) = std::log(std::max(1e-6, px[i].v) / std::max(1e-3 * mean, fit[int(i)]));
      w.at<double>(px[i].y - y0, px[i].x - x0) = 1;
    }
  cv::Mat qs, ws;
  cv::boxFilter(q, qs, -1, cv::Size(3, 3), cv::Point(-1, -1), false, cv::BORDER_CONSTANT);
  cv::boxFilter(w, ws, -1, cv::Size(3, 3), cv::Point(-1, -1), false, cv::BORDER_CONSTANT);
  double s = 0;
  long n = 0;
  for (int y = 0; y + 1 < q.rows; ++y)
    for (int x = 0; x + 1 < q.cols; ++x) {
      if (w.at<double>(y, x) == 0) continue;
      const double a = qs.at<double>(y, x) / ws.at<double>(y, x);
      if (w.at<double>(y, x + 1) > 0) s += std::abs(qs.at<double>(y, x + 1) / ws.at<double>(y, x + 1) - a), ++n;
      if (w.at<double>(y + 1, x) > 0) s += std::abs(qs.at<double>(y + 1, x) / ws.at<double>(y + 1, x) - a), ++n;
    }
  out.unexplained_texture = n > 0 ? s / double(n) : 0;
  return out;
}

// `other` overlaps `ball` and is a ball-sized circle (radius within a factor 2): a ball that may
// hide part of it (a large background circle behind the rig is no such thing).
bool overlapping_ball(const BallLocation& other, const BallLocation& ball) {
  return (other.centre_px - ball.centre_px).norm() < other.radius_px + ball.radius_px &&
         other.radius_px > 0.5 * ball.radius_px && other.radius_px < 2 * ball.radius_px;
}

bool inside_disc(const BallCandidate& a, const BallCandidate& b) {  // a's disc mostly inside b's
  return a.loc.radius_px < b.loc.radius_px &&
         (a.loc.centre_px - b.loc.centre_px).norm() + 0.5 * a.loc.radius_px <= b.loc.radius_px;
}

double diameter_or_one(const ListedBall& b) { return b.diameter_m.value_or(1.0); }

// Camera distance in units of the ball's radius: 1 / sin(alpha).
Vec3 centre_in_radii(const BallCone& c) { return c.axis.normalized() / std::sin(c.half_angle); }

}  // namespace

void measure_outline(BallCandidate& c, const LensModel& lens) {
  const BallLocation& loc = c.loc;
  // Inliers within the fit's threshold or 0.3% of the radius, whichever is larger: a large ball's
  // outline in a real photo (JPEG, demosaicing, a limb that reflects what lies behind it) scatters
  // by a fixed share of its size, not by a fixed pixel count.
  const double tol = std::max(ConeFitOptions{}.inlier_px, 0.003 * loc.radius_px);
  int inliers = 0;
  for (double r : loc.fit.residual_px) inliers += std::abs(r) < tol;
  c.inlier_fraction = loc.outline_px.empty() ? 0 : double(inliers) / double(loc.outline_px.size());
  c.outline_support = loc.outline_support(tol);
  const std::vector<Vec2> outline = cone_outline(loc.fit.cone, lens, 128);
  int inside = 0;
  for (const Vec2& q : outline) inside += q.allFinite() && lens.in_image(q, 0.5);
  c.frame_fraction = double(inside) / double(outline.size());
  c.cut = inside < int(outline.size());
}

namespace {

BallCandidate measure(const cv::Mat& image, const LensModel& lens, const BallLocation& loc,
                      const std::vector<Disc>& ex) {
  BallCandidate c;
  c.loc = loc;
  measure_outline(c, lens);
  // The box reaches the farthest neighbour a measure reads: 0.96 radii plus its step, r / 64.
  const LogLum l(image, loc.centre_px, loc.radius_px + std::lround(loc.radius_px / 64) + 3);
  c.texture = disc_texture(image, l, loc.centre_px, loc.radius_px, ex);
  c.rim_texture = disc_rim_texture(image, l, loc.centre_px, loc.radius_px, ex);
  c.mirror_score = disc_mirror_score(image, loc.centre_px, loc.radius_px, ex);
  c.rim_radial = disc_rim_radial(image, l, loc.centre_px, loc.radius_px, ex);
  const LambertFit lf = lambert_fit(image, lens, loc, ex);
  c.diffuse_residual = lf.residual;
  c.shading_texture = lf.unexplained_texture;
  return c;
}

}  // namespace

BallCandidate measure_ball(const cv::Mat& image, const LensModel& lens, const BallLocation& loc) {
  return measure(image, lens, loc, {});
}

bool acceptable_outline(const BallCandidate& c, const BallSearchOptions& o) {
  return c.inlier_fraction >= o.min_inlier_fraction && c.outline_support >= o.min_outline_support &&
         c.loc.fit.rms_px <= o.max_rms_px && c.frame_fraction >= o.min_frame_fraction;
}

std::vector<BallCandidate> find_ball_candidates(const cv::Mat& image, const LensModel& lens, const BallSearchOptions& o,
                                                std::optional<BallLocation>* frame_out) {
  const double m = std::min(lens.width(), lens.height());
  const double rmin = o.min_radius_px > 0 ? o.min_radius_px : std::max(4.0, m / 40);
  const double rmax = o.max_radius_px > 0 ? o.max_radius_px : m / 2;
  std::vector<BallGuess> guesses = detect_balls(image, rmin, rmax, 64, o.per_band);
  // A photo cropped to the ball (the usual form of chrome-ball data): its outline touches or
  // leaves the frame, where Hough sees too little of it. The frame-filling circle is one more
  // guess, tried first; it must earn its place like any other (outline, appearance).
  if (rmax >= 0.45 * m)
    guesses.insert(guesses.begin(), BallGuess{Vec2(0.5 * (lens.width() - 1), 0.5 * (lens.height() - 1)), 0.5 * m});
  std::vector<BallCandidate> balls;
  // The frame-filling circle as located, even where its outline misses the gates (for
  // view_candidates: a crop's ball whose limb shows little contrast).
  std::optional<BallLocation> frame_circle;
  double frame_support = 0;
  for (const BallGuess& g : guesses) {
    // A guess on a ball already located is not located again.
    bool known = false;
    for (const BallCandidate& b : balls)
      known |= (b.loc.centre_px - g.centre_px).norm() < 0.3 * b.loc.radius_px &&
               std::abs(b.loc.radius_px - g.radius_px) < 0.3 * b.loc.radius_px;
    if (known) continue;
    const bool frame_guess = &g == &guesses.front() && rmax >= 0.45 * m;  // inserted first above
    // Hough radii in a textured scene are rough: the guess, then 0.8 and 1.25 times it. The frame's
    // circle is only where a crop's ball usually is: 0.9 times it too (a ball filling 80-95% of the
    // frame, off centre, is 5-10% from it, where the outline search can lock onto the horizon the
    // ball reflects).
    const std::vector<double> scales =
        frame_guess ? std::vector<double>{1.0, 0.9, 0.8, 1.25} : std::vector<double>{1.0, 0.8, 1.25};
    for (double scale : scales) {
      // The frame's circle searches its lines up to the frame (a crop's ball leaves it) and, in
      // case the ball's outline runs along the frame's edge, where that clipped search finds only
      // what the ball reflects, also skipping the lines that leave it; the better outline wins.
      std::optional<BallLocation> best;
      std::optional<BallCandidate> best_c;
      for (const bool clip : frame_guess ? std::vector<bool>{true, false} : std::vector<bool>{false}) {
        BallLocation l;
        try {
          BallLocateOptions lo;
          lo.clip_lines = clip;
          l = locate_ball(image, lens, {g.centre_px, g.radius_px * scale}, lo);
        } catch (const std::invalid_argument&) {
          continue;
        }
        // A straight edge fits a huge circle: the radius must stay near the detection range and the
        // centre in the image.
        if (!(l.radius_px >= rmin / 1.25 && l.radius_px <= 1.25 * rmax) || !lens.in_image(l.centre_px)) continue;
        // The outline's measures choose; the appearance is measured below, once, for a circle whose
        // outline passes (most guesses' do not).
        BallCandidate lc;
        lc.loc = l;
        measure_outline(lc, lens);
        if (!best_c || lc.outline_support > best_c->outline_support) best = l, best_c = lc;
      }
      if (!best) continue;
      const BallLocation loc = *best;
      BallCandidate c = *best_c;
      // The frame-filling guess's circle, kept for view_candidates when its outline is weak: the
      // best supported of its scales.
      if (frame_guess && fills_frame(loc.radius_px, lens.width(), lens.height()) && c.outline_support >= 0.3 &&
          c.inlier_fraction >= 0.4 && c.loc.fit.rms_px <= o.max_rms_px &&
          (!frame_circle || c.outline_support > frame_support))
        frame_circle = loc, frame_support = c.outline_support;
      // The frame-filling guess stands for a crop's ball: a circle it finds that does not fill the
      // frame is left to the Hough guesses (their own starts locate it better).
      if (frame_guess && !fills_frame(loc.radius_px, lens.width(), lens.height())) continue;
      if (!acceptable_outline(c, o)) continue;
      c = measure_ball(image, lens, loc);
      auto same =
          std::find_if(balls.begin(), balls.end(), [&](const BallCandidate& b) { return same_circle(b.loc, loc); });
      if (same == balls.end())
        balls.push_back(c);
      else if (loc.fit.inliers > same->loc.fit.inliers)
        *same = c;
      break;
    }
  }
  // A textured circle that is not a mirror's outline may be a reflection inside one whose own
  // outline Hough missed: located again from 1.4 and 1.8 times its radius.
  const std::size_t found = balls.size();
  for (std::size_t i = 0; i < found; ++i) {
    if (!(balls[i].texture >= 0.08)) continue;
    for (double scale : {1.4, 1.8}) {
      BallLocation loc;
      try {
        loc = locate_ball(image, lens, {balls[i].loc.centre_px, balls[i].loc.radius_px * scale});
      } catch (const std::invalid_argument&) {
        continue;
      }
      if (!(loc.radius_px >= rmin / 1.25 && loc.radius_px <= 1.25 * rmax) || !lens.in_image(loc.centre_px)) continue;
      BallCandidate c;
      c.loc = loc;
      measure_outline(c, lens);
      if (!acceptable_outline(c, o)) continue;
      c = measure_ball(image, lens, loc);
      if (!looks_like(c, BallKind::chrome) || !inside_disc(balls[i], c)) continue;
      bool dup = false;
      for (const BallCandidate& b : balls) dup |= same_circle(b.loc, loc);
      if (!dup) balls.push_back(c);
      break;
    }
  }
  // A circle inside a mirror's disc is something the mirror reflects, not a ball (a circle inside a
  // large smooth circle, a lamp or a plate behind the rig, may well be a ball). A larger circle that
  // looks like a mirror only for the ball in front of it (a sphere or a target behind the chrome
  // ball) is measured again without that ball's disc: if it no longer looks like one, it is the
  // thing behind, and the ball inside stays.
  for (std::size_t k = 0; k < balls.size(); ++k) {
    if (!looks_like(balls[k], BallKind::chrome)) continue;
    for (std::size_t i = 0; i < balls.size(); ++i) {
      if (i == k || !inside_disc(balls[i], balls[k]) || !looks_like(balls[i], BallKind::chrome)) continue;
      if (!(balls[i].inlier_fraction >= 0.8 && balls[i].loc.fit.rms_px <= 0.5)) continue;  // a clean outline of its own
      const BallCandidate without =
          measure(image, lens, balls[k].loc, {{balls[i].loc.centre_px, balls[i].loc.radius_px}});
      if (!looks_like(without, BallKind::chrome)) {
        balls[k].texture = without.texture, balls[k].rim_texture = without.rim_texture;
        balls[k].mirror_score = without.mirror_score, balls[k].diffuse_residual = without.diffuse_residual;
        balls[k].rim_radial = without.rim_radial;
        balls[k].shading_texture = without.shading_texture;
        break;
      }
    }
  }
  std::vector<BallCandidate> out;
  for (std::size_t i = 0; i < balls.size(); ++i) {
    bool inside = false;
    for (std::size_t k = 0; k < balls.size(); ++k)
      inside |= k != i && inside_disc(balls[i], balls[k]) && looks_like(balls[k], BallKind::chrome);
    if (!inside) out.push_back(balls[i]);
  }
  // Where two candidates overlap one hides part of the other: their appearance is measured again
  // without the other's disc (its outline and frame measures stay).
  const std::vector<BallCandidate> kept = out;
  for (std::size_t i = 0; i < out.size(); ++i) {
    std::vector<Disc> ex;
    for (std::size_t k = 0; k < kept.size(); ++k)
      if (k != i && overlapping_ball(kept[k].loc, kept[i].loc))
        ex.push_back({kept[k].loc.centre_px, kept[k].loc.radius_px});
    if (ex.empty()) continue;
    const BallCandidate m = measure(image, lens, kept[i].loc, ex);
    out[i].texture = m.texture, out[i].rim_texture = m.rim_texture, out[i].mirror_score = m.mirror_score;
    out[i].rim_radial = m.rim_radial;
    out[i].diffuse_residual = m.diffuse_residual, out[i].shading_texture = m.shading_texture;
  }
  if (frame_out) *frame_out = frame_circle;
  std::stable_sort(out.begin(), out.end(), [](const BallCandidate& a, const BallCandidate& b) {
    return a.loc.fit.inliers > b.loc.fit.inliers;
  });
  return out;
}

std::vector<ListedBall> listed_balls(const PhotoSet& set) {
  std::vector<ListedBall> out;
  for (const BallSpec& b : set.balls) out.push_back({b.name, b.kind, b.diameter_m});
  return out;
}

// Thresholds measured on rendered balls (datasets-synthetic: the lobby, park, studio and warehouse
// shoots, the analytic sky): chrome balls in textured surroundings have 40-60% of their rim
// textured and a Lambert residual of 0.3-4, those in a smooth sky 3-8% and 11-14 (the sun); grey
// balls fit the Lambert shading within 1-5% (10% where a nearer ball hides part of one; 1-2% lit
// by a clipped sun from any side, leaving a shading texture of 0.002-0.004 where a chrome ball in a
// smooth sky leaves 0.06-0.35); ringed
// targets texture 5-15% of the disc's rim with residuals of 0.3-1.7; flat discs fit it within 1%
// (only size and the rig's geometry tell those from a grey ball).
bool looks_like(const BallCandidate& c, BallKind kind) {
  if (!std::isfinite(c.diffuse_residual)) return false;  // too little of it visible to tell
  switch (kind) {
    // A textured rim with the world compressed across it (rim_radial: a circle drawn over a patch
    // of the scene scores about 0, a chrome ball well above 0.2; docs/tradeoffs.md, "Measured
    // choices in the code"), or a range no diffuse
    // ball shows (a light source reflected: the sun in a smooth sky, which has no features to
    // compress: its horizon crosses the ball as a line through the centre).
    case BallKind::chrome:
      return (c.rim_texture >= 0.25 && c.rim_radial >= 0.2 && c.diffuse_residual >= 0.12) || c.diffuse_residual >= 2.0;
    case BallKind::grey: return c.shading_texture < 0.05 && c.diffuse_residual < 0.15;
    case BallKind::glossy: return c.diffuse_residual >= 0.04;
  }
  return false;
}

namespace {

// How well a candidate fits a kind, in [0, 1] (0 when it does not look like one).
double appearance(const BallCandidate& c, BallKind kind) {
  if (!looks_like(c, kind)) return 0;
  switch (kind) {
    case BallKind::chrome: return std::min(1.0, c.texture / 0.2);
    case BallKind::grey: return 1 - std::min(1.0, c.diffuse_residual / 0.15);
    case BallKind::glossy: return 0.5;
  }
  return 0;
}

}  // namespace

std::vector<int> assign_balls_in_view(const std::vector<BallCandidate>& cands, const std::vector<ListedBall>& balls) {
  const int k = int(balls.size()), m = int(cands.size());
  std::vector<int> best(std::size_t(k), -1), cur(std::size_t(k), -1);
  double best_score = -1e300;
  // Distance from the camera in units of the ball's listed diameter (1 when unknown): similar for
  // the balls of one rig (within a factor 2.5; penalised beyond 1.5: a rig 15 cm deep seen from
  // 45 cm is 1.33).
  auto distance = [&](int b, int c) {
    return diameter_or_one(balls[std::size_t(b)]) / std::sin(cands[std::size_t(c)].loc.fit.cone.half_angle);
  };
  std::function<void(int, double)> search = [&](int b, double score) {
    if (b == k) {
      if (score > best_score) best_score = score, best = cur;
      return;
    }
    cur[std::size_t(b)] = -1;
    search(b + 1, score);
    for (int c = 0; c < m; ++c) {
      if (std::find(cur.begin(), cur.begin() + b, c) != cur.begin() + b) continue;
      const double app = appearance(cands[std::size_t(c)], balls[std::size_t(b)].kind);
      if (!(app > 0)) continue;
      double s = score + 1 + app * cands[std::size_t(c)].frame_fraction;
      bool ok = true;
      for (int a = 0; a < b && ok; ++a) {
        if (cur[std::size_t(a)] < 0) continue;
        const double q = std::abs(std::log(distance(b, c) / distance(a, cur[std::size_t(a)])));
        if (q > std::log(2.5))
          ok = false;
        else
          s -= std::max(0.0, q - std::log(1.5)) * 4;
      }
      if (!ok) continue;
      cur[std::size_t(b)] = c;
      search(b + 1, s);
      cur[std::size_t(b)] = -1;
    }
  };
  search(0, 0);
  return best;
}

RigSuspects rig_suspects(const std::vector<double>& disagreement, const RigSuspectOptions& options) {
  RigSuspects out;
  out.suspect.assign(disagreement.size(), 0);
  std::vector<double> checked;
  for (double d : disagreement)
    if (d >= 0) checked.push_back(d);
  if (checked.size() < 3) return out;
  std::nth_element(checked.begin(), checked.begin() + checked.size() / 2, checked.end());
  out.median = checked[checked.size() / 2];
  out.limit = std::max(options.radii, options.median_factor * out.median);
  for (std::size_t v = 0; v < disagreement.size(); ++v) out.suspect[v] = disagreement[v] > out.limit;
  return out;
}

BallCone predicted_cone(const BallCone& chrome, const Mat3& world_from_cam, const Vec3& offset, double scale) {
  const Vec3 b = centre_in_radii(chrome) + world_from_cam.transpose() * offset;  // chrome radii, camera frame
  BallCone cone;
  cone.axis = b.normalized();
  cone.half_angle = std::asin(std::clamp(scale / b.norm(), 1e-9, 1 - 1e-9));
  return cone;
}

namespace {

// The offset (world, chrome radii) a candidate implies for a ball of radius `scale`.
Vec3 implied_offset(const ViewBalls& v, const BallCandidate& c, double scale) {
  return v.world_from_cam * (scale * centre_in_radii(c.loc.fit.cone) - centre_in_radii(*v.chrome));
}

double tolerance(const RigOptions& o, const ViewBalls& v, const BallCone& ball, double scale) {
  return o.tolerance +
         o.relative_tolerance * 0.5 * (centre_in_radii(*v.chrome).norm() + scale * centre_in_radii(ball).norm());
}

// A candidate on the ball of `cone`: centres within half its radius, radii within 30%.
bool same_ball(const BallCandidate& c, const BallCone& cone) {
  return angle_between(c.loc.fit.cone.axis, cone.axis) < 0.5 * cone.half_angle &&
         std::abs(c.loc.fit.cone.half_angle - cone.half_angle) < 0.3 * cone.half_angle;
}

// A smaller circle mostly inside the chrome ball's disc: something it reflects.
bool nested_in(const BallCandidate& c, const BallCone& chrome) {
  const double a = c.loc.fit.cone.half_angle;
  return a < chrome.half_angle && angle_between(c.loc.fit.cone.axis, chrome.axis) + 0.5 * a <= chrome.half_angle;
}

// Least squares (scale, offset) over observations R_i (s g_i - c_i) = o: 3 equations each.
std::pair<double, Vec3> solve_scale_offset(const std::vector<Mat3>& r, const std::vector<Vec3>& g,
                                           const std::vector<Vec3>& c) {
  Eigen::MatrixXd a(3 * int(r.size()), 4);
  Eigen::VectorXd b(3 * int(r.size()));
  for (std::size_t i = 0; i < r.size(); ++i) {
    a.block<3, 1>(3 * int(i), 0) = r[i] * g[i];
    a.block<3, 3>(3 * int(i), 1) = -Mat3::Identity();
    b.segment<3>(3 * int(i)) = r[i] * c[i];
  }
  const Eigen::VectorXd x = a.colPivHouseholderQr().solve(b);
  return {x[0], x.segment<3>(1)};
}

}  // namespace

std::vector<RigMember> fit_ball_rig(const std::vector<ViewBalls>& views, const std::vector<ListedBall>& balls,
                                    const RigOptions& o) {
  std::vector<RigMember> rig(balls.size());
  int anchor = -1;
  for (std::size_t b = 0; b < balls.size(); ++b)
    if (balls[b].kind == BallKind::chrome) {
      anchor = int(b);
      break;
    }
  if (anchor < 0) return rig;
  rig[std::size_t(anchor)] = {true, Vec3::Zero(), 1.0, true, 0, 0};
  std::vector<int> anchored;
  for (std::size_t i = 0; i < views.size(); ++i)
    if (views[i].chrome) anchored.push_back(int(i));
  rig[std::size_t(anchor)].support = int(anchored.size());
  // Candidates already claimed, per view: the anchor's own.
  std::vector<std::vector<char>> claimed(views.size());
  for (std::size_t i = 0; i < views.size(); ++i) {
    claimed[i].assign(views[i].candidates.size(), 0);
    if (views[i].chrome)
      for (std::size_t c = 0; c < views[i].candidates.size(); ++c)
        if (same_ball(views[i].candidates[c], *views[i].chrome) || nested_in(views[i].candidates[c], *views[i].chrome))
          claimed[i][c] = 1;
  }
  const int need = std::max(1, std::min(o.min_support, int(anchored.size())));
  for (std::size_t b = 0; b < balls.size(); ++b) {
    if (int(b) == anchor) continue;
    const ListedBall& lb = balls[b];
    const ListedBall& ab = balls[std::size_t(anchor)];
    const bool scale_given = lb.diameter_m && ab.diameter_m;
    const double given_scale = scale_given ? *lb.diameter_m / *ab.diameter_m : 1.0;
    struct Obs {
      int view, cand;
    };
    std::vector<Obs> obs;
    for (int i : anchored)
      for (std::size_t c = 0; c < views[std::size_t(i)].candidates.size(); ++c)
        if (!claimed[std::size_t(i)][c] && looks_like(views[std::size_t(i)].candidates[c], lb.kind))
          obs.push_back({i, int(c)});
    // Support of a hypothesis: per view, the agreeing candidate nearest it.
    auto support = [&](double s, const Vec3& off, std::vector<Obs>* who, double* sum2) {
      int n = 0;
      double e2 = 0;
      for (int i : anchored) {
        const ViewBalls& v = views[std::size_t(i)];
        int best = -1;
        double best_d = 1e300;
        for (const Obs& ob : obs) {
          if (ob.view != i) continue;
          const BallCandidate& c = v.candidates[std::size_t(ob.cand)];
          const double d = (implied_offset(v, c, s) - off).norm();
          if (d < tolerance(o, v, c.loc.fit.cone, s) && d < best_d) best = ob.cand, best_d = d;
        }
        if (best >= 0) {
          ++n, e2 += best_d * best_d;
          if (who) who->push_back({i, best});
        }
      }
      if (sum2) *sum2 = e2;
      return n;
    };
    int best_n = 0;
    double best_e2 = 1e300, best_s = given_scale;
    Vec3 best_off = Vec3::Zero();
    auto consider = [&](double s, const Vec3& off) {
      if (!(s > 0.05 && s < 20) || !off.allFinite()) return;
      double e2 = 0;
      const int n = support(s, off, nullptr, &e2);
      if (n > best_n || (n == best_n && e2 < best_e2)) best_n = n, best_e2 = e2, best_s = s, best_off = off;
    };
    if (scale_given) {
      for (const Obs& ob : obs)
        consider(given_scale,
                 implied_offset(views[std::size_t(ob.view)],
                                views[std::size_t(ob.view)].candidates[std::size_t(ob.cand)], given_scale));
    } else {
      for (std::size_t p = 0; p < obs.size(); ++p)
        for (std::size_t q = p + 1; q < obs.size(); ++q) {
          if (obs[p].view == obs[q].view) continue;
          std::vector<Mat3> r;
          std::vector<Vec3> g, c;
          for (const Obs* ob : {&obs[p], &obs[q]}) {
            const ViewBalls& v = views[std::size_t(ob->view)];
            r.push_back(v.world_from_cam);
            g.push_back(centre_in_radii(v.candidates[std::size_t(ob->cand)].loc.fit.cone));
            c.push_back(centre_in_radii(*v.chrome));
          }
          const auto [s, off] = solve_scale_offset(r, g, c);
          consider(s, off);
        }
      if (anchored.size() == 1 && !obs.empty())
        consider(given_scale,
                 implied_offset(views[std::size_t(obs[0].view)],
                                views[std::size_t(obs[0].view)].candidates[std::size_t(obs[0].cand)], given_scale));
    }
    if (best_n < need) continue;
    // Refit on the supporters (twice: the support may grow).
    for (int pass = 0; pass < 2; ++pass) {
      std::vector<Obs> who;
      support(best_s, best_off, &who, nullptr);
      if (int(who.size()) < need) break;
      std::vector<Mat3> r;
      std::vector<Vec3> g, c;
      Vec3 mean = Vec3::Zero();
      for (const Obs& ob : who) {
        const ViewBalls& v = views[std::size_t(ob.view)];
        r.push_back(v.world_from_cam);
        g.push_back(centre_in_radii(v.candidates[std::size_t(ob.cand)].loc.fit.cone));
        c.push_back(centre_in_radii(*v.chrome));
        mean += implied_offset(v, v.candidates[std::size_t(ob.cand)], best_s);
      }
      if (scale_given || who.size() < 2) {
        best_off = mean / double(who.size());
      } else {
        const auto [s, off] = solve_scale_offset(r, g, c);
        if (s > 0.05 && s < 20 && off.allFinite()) best_s = s, best_off = off;
      }
    }
    std::vector<Obs> who;
    double e2 = 0;
    const int n = support(best_s, best_off, &who, &e2);
    if (n < need) continue;
    for (const Obs& ob : who) claimed[std::size_t(ob.view)][std::size_t(ob.cand)] = 1;
    rig[b] = {true, best_off, best_s, scale_given, n, std::sqrt(e2 / n)};
  }
  return rig;
}

BallLocation refit_outline_excluding(const BallLocation& ball, const LensModel& lens,
                                     const std::vector<BallLocation>& others) {
  std::vector<Vec3> rays;
  std::vector<Vec2> kept;
  for (const Vec2& p : ball.outline_px) {
    bool on_other = false;
    for (const BallLocation& o : others)
      on_other |= (p - o.centre_px).norm() <= o.radius_px + std::max(2.0, 0.05 * o.radius_px);
    if (!on_other) rays.push_back(lens.unproject(p)), kept.push_back(p);
  }
  if (kept.size() == ball.outline_px.size() || kept.size() < 16) return ball;
  BallLocation out = ball;
  try {
    out.fit = fit_cone(rays, lens);
  } catch (const std::invalid_argument&) {
    return ball;
  }
  out.outline_px = kept;
  const ConeCircle circle = cone_circle(out.fit.cone, lens);
  out.centre_px = circle.centre_px;
  out.radius_px = circle.radius_px;
  return out;
}

bool same_circle(const BallLocation& a, const BallLocation& b) {
  const double r = std::min(a.radius_px, b.radius_px);
  return (a.centre_px - b.centre_px).norm() < 0.5 * r && std::abs(a.radius_px - b.radius_px) < 0.3 * r;
}

BallCandidate given_ball(const cv::Mat& image, const LensModel& lens, const BallGuess& guess) {
  // A circle given by hand is usually within a few percent; the locator's default band (25% of the
  // radius) also holds the circles of reflections inside a chrome ball, which win where the limb
  // barely differs from what lies behind it. Of the bands that find an outline, the one whose
  // circle shows the most of its outline wins (the narrowest on a tie).
  std::optional<BallCandidate> best;
  std::string why;
  for (double band : {0.06, 0.12, 0.25}) {
    BallLocateOptions o;
    o.search_fraction = band;
    try {
      BallCandidate c = measure_ball(image, lens, locate_ball(image, lens, guess, o));
      if (!best || c.outline_support > best->outline_support) best = std::move(c);
    } catch (const std::invalid_argument& e) {
      if (why.empty()) why = e.what();
    }
  }
  if (!best) throw std::invalid_argument(why);
  return *best;
}

std::optional<AnchorFromRig> anchor_from_rig(const ViewBalls& view, const std::vector<RigMember>& rig,
                                             const std::vector<ListedBall>& balls, const RigOptions& ro) {
  if (view.chrome || rig.size() != balls.size()) return std::nullopt;
  // A ball b found at g (its radii, camera frame) puts the chrome ball's centre at
  //   c = s_b g - R^T o_b   (chrome radii, camera frame; o_b = R (s_b g - c) solved for c).
  // The candidate nearest such a c, within the rig's tolerance, is the chrome ball; the hypothesis
  // with the most members agreeing, then the smallest disagreement, wins.
  std::optional<AnchorFromRig> best;
  int best_support = 0;
  double best_d = 1e300;
  for (std::size_t b = 0; b < balls.size(); ++b) {
    if (balls[b].kind == BallKind::chrome || !rig[b].known) continue;
    for (std::size_t k = 0; k < view.candidates.size(); ++k) {
      if (!looks_like(view.candidates[k], balls[b].kind)) continue;
      const Vec3 c = rig[b].scale * centre_in_radii(view.candidates[k].loc.fit.cone) -
                     view.world_from_cam.transpose() * rig[b].offset;
      const double tol = ro.tolerance + ro.relative_tolerance * c.norm();
      for (std::size_t j = 0; j < view.candidates.size(); ++j) {
        if (j == k) continue;
        const double d = (centre_in_radii(view.candidates[j].loc.fit.cone) - c).norm();
        if (!(d < tol)) continue;
        // Support: the other members that a candidate confirms, placed from this chrome ball.
        ViewBalls anchored = view;
        anchored.chrome = view.candidates[j].loc.fit.cone;
        int support = 1;
        for (std::size_t m = 0; m < balls.size(); ++m) {
          if (m == b || balls[m].kind == BallKind::chrome || !rig[m].known) continue;
          for (std::size_t q = 0; q < view.candidates.size(); ++q)
            if (q != j && q != k && looks_like(view.candidates[q], balls[m].kind) &&
                (implied_offset(anchored, view.candidates[q], rig[m].scale) - rig[m].offset).norm() < tol) {
              ++support;
              break;
            }
        }
        if (support > best_support || (support == best_support && d < best_d)) {
          best_support = support, best_d = d;
          best = AnchorFromRig{view.candidates[j].loc.fit.cone, balls[b].name, d};
        }
      }
    }
  }
  return best;
}

std::vector<BallFinding> identify_view_balls(const ViewBalls& view, const std::vector<RigMember>& rig,
                                             const std::vector<ListedBall>& balls, const cv::Mat& image,
                                             const LensModel& lens, const RigOptions& ro, const BallSearchOptions& so,
                                             bool trust_view) {
  std::vector<BallFinding> out(balls.size());
  std::vector<char> claimed(view.candidates.size(), 0);
  const std::vector<int> own = assign_balls_in_view(view.candidates, balls);
  // The anchor first: the others are measured without the discs of balls already found.
  std::vector<std::size_t> order;
  for (std::size_t b = 0; b < balls.size(); ++b)
    if (balls[b].kind == BallKind::chrome) order.push_back(b);
  for (std::size_t b = 0; b < balls.size(); ++b)
    if (balls[b].kind != BallKind::chrome) order.push_back(b);
  for (std::size_t b : order) {
    BallFinding& f = out[b];
    const RigMember& m = rig.size() == balls.size() ? rig[b] : RigMember{};
    if (balls[b].kind == BallKind::chrome && m.known && m.offset.isZero() && view.chrome) {
      // The anchor: the view's chrome ball (its candidate when one coincides, for the measures).
      BallCandidate c;
      bool have = false;
      for (std::size_t k = 0; k < view.candidates.size(); ++k) {
        if (nested_in(view.candidates[k], *view.chrome)) claimed[k] = 1;
        if (same_ball(view.candidates[k], *view.chrome)) c = view.candidates[k], claimed[k] = 1, have = true;
      }
      if (!have) {
        BallLocation loc;
        loc.fit.cone = *view.chrome;
        const ConeCircle circle = cone_circle(*view.chrome, lens);
        loc.centre_px = circle.centre_px;
        loc.radius_px = circle.radius_px;
        c = measure_ball(image, lens, loc);
        c.inlier_fraction = 1;
      }
      c.loc.fit.cone = *view.chrome;
      f.status = "found";
      f.note = view.anchor_note.empty() ? "chrome ball (the orientation's anchor)" : view.anchor_note;
      f.ball = c;
      f.disagreement = 0;
      continue;
    }
    if (!view.chrome || !m.known) {
      if (trust_view && own[b] >= 0) {
        f.status = "found";
        f.ball = view.candidates[std::size_t(own[b])];
        f.note = "identified in this view alone (appearance and size)";
      } else {
        f.note = !view.chrome ? "no chrome ball in this view to place it by" : "too few views agree where this ball is";
      }
      continue;
    }
    const BallCone pred = predicted_cone(*view.chrome, view.world_from_cam, m.offset, m.scale);
    const ConeCircle predicted = cone_circle(pred, lens);
    const Vec2 pc = predicted.centre_px;
    const double pr = predicted.radius_px;
    f.predicted_px = pc;
    f.predicted_radius_px = pr;
    const double tol = tolerance(ro, view, pred, m.scale);
    // The agreeing candidate nearest the prediction.
    int best = -1;
    double best_d = 1e300;
    for (std::size_t k = 0; k < view.candidates.size(); ++k) {
      if (claimed[k] || !looks_like(view.candidates[k], balls[b].kind)) continue;
      const double d = (implied_offset(view, view.candidates[k], m.scale) - m.offset).norm();
      if (d < tol && d < best_d) best = int(k), best_d = d;
    }
    if (best >= 0) {
      claimed[std::size_t(best)] = 1;
      f.status = "found";
      f.ball = view.candidates[std::size_t(best)];
      f.disagreement = best_d;
      f.note = "agrees with the rig within " + std::to_string(best_d).substr(0, 4) + " chrome radii";
      continue;
    }
    if (!pc.allFinite() || !lens.in_image(pc, -pr)) {
      f.note = "outside the frame (predicted at " + px_text(pc, pr) + ")";
      continue;
    }
    // Hidden behind a nearer ball of the view (the chrome's or another found one)?
    auto hidden_by = [&](const BallCone& other) {
      const double gap = angle_between(other.axis, pred.axis);
      return gap + 0.5 * pred.half_angle < other.half_angle &&
             centre_in_radii(other).norm() < centre_in_radii(pred).norm() * m.scale;
    };
    if (hidden_by(*view.chrome)) {
      f.note = "hidden behind the chrome ball (predicted at " + px_text(pc, pr) + ")";
      continue;
    }
    // Search at the prediction.
    try {
      BallLocateOptions lo;
      lo.search_fraction = 0.15;
      const BallLocation loc = locate_ball(image, lens, {pc, pr}, lo);
      std::vector<Disc> ex;
      for (const BallFinding& g : out)
        if (g.ball && overlapping_ball(g.ball->loc, loc)) ex.push_back({g.ball->loc.centre_px, g.ball->loc.radius_px});
      const BallCandidate c = measure(image, lens, loc, ex);
      const double d = (implied_offset(view, c, m.scale) - m.offset).norm();
      if (acceptable_outline(c, so) && looks_like(c, balls[b].kind) && d < tol) {
        f.status = "found at the predicted place";
        f.ball = c;
        f.disagreement = d;
        f.note = "no Hough candidate; located at the place the other views predict";
        continue;
      }
      std::ostringstream s;
      s.precision(2);
      s << "the outline at the predicted place " << px_text(pc, pr) << " does not qualify (inliers "
        << c.inlier_fraction << ", RMS " << c.loc.fit.rms_px << " px, "
        << (looks_like(c, balls[b].kind) ? "" : "does not look " + std::string(to_string(balls[b].kind)) + ", ") << d
        << " chrome radii from the rig's place)";
      f.note = s.str();
    } catch (const std::invalid_argument& e) {
      f.note = "no outline at the predicted place " + px_text(pc, pr);
    }
  }
  return out;
}

ViewCandidates view_candidates(const cv::Mat& image, const LensModel& lens, const std::vector<ListedBall>& balls,
                               const BallSearchOptions& search) {
  ViewCandidates vc;
  std::optional<BallLocation> frame_circle;
  vc.cands = find_ball_candidates(image, lens, search, balls.size() == 1 ? &frame_circle : nullptr);
  // A photo of one listed ball whose frame a circle fills, even with a weak outline: the circles
  // inside it are what that ball reflects (a crop's chrome ball whose limb shows little contrast
  // against a table), never the ball.
  if (frame_circle) {
    std::vector<BallCandidate> kept;
    for (const BallCandidate& b : vc.cands)
      if (same_circle(b.loc, *frame_circle) ||
          (b.loc.centre_px - frame_circle->centre_px).norm() + 0.5 * b.loc.radius_px > frame_circle->radius_px)
        kept.push_back(b);
    vc.cands = std::move(kept);
    // Its outline supported along half its length or more, but with too few inliers among all
    // its lines to pass the search's gate (an edge-on-edge limb against a table): still the one
    // ball of a crop, taken below as any clean frame-filling circle is.
    const bool listed = std::any_of(vc.cands.begin(), vc.cands.end(),
                                    [&](const BallCandidate& b) { return same_circle(b.loc, *frame_circle); });
    if (!listed) {
      const BallCandidate fc = measure_ball(image, lens, *frame_circle);
      if (fc.outline_support >= search.min_outline_support && fc.loc.fit.rms_px <= search.max_rms_px)
        vc.cands.insert(vc.cands.begin(), fc);
    }
  }
  vc.pick = assign_balls_in_view(vc.cands, balls);
  // A photo cropped to its one listed ball (calib/lens/far_camera.h): the one circle with a clean
  // outline that fills the frame is that ball whatever its texture (a chrome ball reflecting a
  // smooth table over half its disc looks glossy), and the circles inside it are reflections. A
  // crop is of the ball: the circle holds the frame's centre and lies mostly inside the frame (a
  // huge arc through the furniture of a full frame, centred near its edge, is no crop's ball).
  if (balls.size() == 1) {
    const Vec2 middle(0.5 * (image.cols - 1), 0.5 * (image.rows - 1));
    int fill = -1, n = 0;
    for (std::size_t k = 0; k < vc.cands.size(); ++k) {
      const BallCandidate& c = vc.cands[k];
      if (fills_frame(c.loc.radius_px, image.cols, image.rows) && c.outline_support >= 0.5 && c.frame_fraction >= 0.7 &&
          (c.loc.centre_px - middle).norm() <= 0.5 * c.loc.radius_px)
        fill = int(k), ++n;
    }
    if (n == 1) vc.pick[0] = fill;
  }
  return vc;
}

std::vector<ChromeRescue> rescue_chrome_balls(const std::vector<std::optional<ViewCandidates>>& views,
                                              const std::vector<ListedBall>& balls, const BallSearchOptions& search) {
  std::vector<ChromeRescue> out(views.size());
  int chrome = -1;
  for (std::size_t b = 0; b < balls.size(); ++b)
    if (balls[b].kind == BallKind::chrome) chrome = chrome < 0 ? int(b) : chrome;
  if (chrome < 0 || !balls[std::size_t(chrome)].diameter_m) return out;
  const double tolerance = 1.0, relative = 0.04;
  for (std::size_t b = 0; b < balls.size(); ++b) {
    if (int(b) == chrome || !balls[b].diameter_m) continue;
    const double scale = *balls[b].diameter_m / *balls[std::size_t(chrome)].diameter_m;
    std::vector<double> d;
    for (const auto& vc : views)
      if (vc && vc->pick[std::size_t(chrome)] >= 0 && vc->pick[b] >= 0)
        d.push_back((centre_in_radii(vc->cands[std::size_t(vc->pick[std::size_t(chrome)])].loc.fit.cone) -
                     scale * centre_in_radii(vc->cands[std::size_t(vc->pick[b])].loc.fit.cone))
                        .norm());
    if (d.size() < 2) continue;
    std::sort(d.begin(), d.end());
    const double rig = d[d.size() / 2];
    int agree = 0;
    for (double x : d) agree += std::abs(x - rig) <= tolerance + relative * rig;
    if (agree < 2) continue;
    for (std::size_t v = 0; v < views.size(); ++v) {
      const auto& vc = views[v];
      if (!vc || vc->pick[std::size_t(chrome)] >= 0 || vc->pick[b] < 0 || out[v].candidate >= 0) continue;
      const BallCandidate& other = vc->cands[std::size_t(vc->pick[b])];
      const Vec3 g = scale * centre_in_radii(other.loc.fit.cone);  // chrome radii, camera frame
      int hit = -1, hits = 0;
      double hit_d = 0;
      for (std::size_t k = 0; k < vc->cands.size(); ++k) {
        const BallCandidate& c = vc->cands[k];
        if (std::find(vc->pick.begin(), vc->pick.end(), int(k)) != vc->pick.end()) continue;
        if (!acceptable_outline(c, search) || looks_like(c, BallKind::grey) || !looks_like(c, BallKind::glossy))
          continue;
        const Vec3 cc = centre_in_radii(c.loc.fit.cone);
        const double dist = (cc - g).norm();
        if (std::abs(dist - rig) <= tolerance + relative * 0.5 * (cc.norm() + g.norm()))
          ++hits, hit = int(k), hit_d = dist;
      }
      if (hits != 1) continue;
      char note[256];
      std::snprintf(note, sizeof note,
                    "chrome ball taken at %.1f chrome radii from the %s ball (the other views agree on %.1f; its rim "
                    "is too smooth for the appearance test)",
                    hit_d, balls[b].name.c_str(), rig);
      out[v] = {hit, note};
    }
  }
  return out;
}

}  // namespace rsibr
