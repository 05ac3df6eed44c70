#include "hdr/vignetting.h"

#include "formats/json_error.h"
#include "hdr/raw_image.h"
#include "formats/image_codecs.h"

#include <Eigen/Dense>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace rsibr {

namespace {

constexpr double kMinV = 0.05;

double poly(const std::array<double, 3>& k, double r2) { return 1 + r2 * (k[0] + r2 * (k[1] + r2 * k[2])); }

double median_of(std::vector<double> v) {
  if (v.empty()) return 0;
  const auto mid = v.begin() + long(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

// One white square: its centre in normalised coordinates (x, y) = (p - c) / r_corner, ln of its value.
struct Square {
  int board;
  double x, y, r2, ln_y;
};

// The white squares of one board (see the header); empty when the board does not look like one.
std::vector<Square> board_squares(const VignettingBoard& b, int board, const ResponseCurve& curve, const Vec2& c,
                                  double r_corner) {
  const int n = b.gridn;
  const double top = curve.max_code;
  struct Cell {
    int i, j;
    double value;
    Vec2 centre;
  };
  std::vector<Cell> cells;
  auto corner = [&](int i, int j) { return b.corners[std::size_t(j * n + i)]; };
  for (int j = 0; j + 1 < n; ++j)
    for (int i = 0; i + 1 < n; ++i) {
      const Vec2 p00 = corner(i, j), p10 = corner(i + 1, j), p01 = corner(i, j + 1), p11 = corner(i + 1, j + 1);
      auto at = [&](double u, double v) {
        return Vec2((1 - v) * ((1 - u) * p00 + u * p10) + v * ((1 - u) * p01 + u * p11));
      };
      std::vector<double> samples;
      bool bad = false;
      for (int sv = 0; sv < 5 && !bad; ++sv)
        for (int su = 0; su < 5 && !bad; ++su) {
          const Vec2 q = at(0.3 + 0.1 * su, 0.3 + 0.1 * sv);
          const int x = int(std::lround(q.x())), y = int(std::lround(q.y()));
          if (x < 0 || y < 0 || x >= b.codes.cols || y >= b.codes.rows) {
            bad = true;
            break;
          }
          const cv::Vec3w z = b.codes.at<cv::Vec3w>(y, x);
          double sum = 0;
          for (int ch = 0; ch < 3; ++ch) {
            const double code = z[ch];
            if (code >= 0.97 * top || code < 0.02 * top) bad = true;
            sum += curve.linear(ch, code);
          }
          samples.push_back(sum);
        }
      if (bad) continue;
      cells.push_back({i, j, median_of(samples), at(0.5, 0.5)});
    }
  if (cells.size() < 8) return {};
  std::vector<double> par[2];
  for (const Cell& cl : cells) par[(cl.i + cl.j) % 2].push_back(cl.value);
  if (par[0].empty() || par[1].empty()) return {};
  const double m0 = median_of(par[0]), m1 = median_of(par[1]);
  const int white = m0 > m1 ? 0 : 1;
  const double w = std::max(m0, m1), k = std::min(m0, m1);
  if (!(w > 3 * k) || !(w > 0)) return {};  // no black/white contrast: not a board's squares
  std::vector<Square> out;
  for (const Cell& cl : cells) {
    if ((cl.i + cl.j) % 2 != white || !(cl.value > 0)) continue;
    const double x = (cl.centre.x() - c.x()) / r_corner, y = (cl.centre.y() - c.y()) / r_corner;
    out.push_back({board, x, y, x * x + y * y, std::log(cl.value)});
  }
  return out;
}

struct Fit {
  std::array<double, 3> k{0, 0, 0};
  std::vector<double> nuisance;  // per board: beta, a, b
  double rms = 0, sigma_corner = 0;
};

// Robust Gauss-Newton of the model over `sq` (boards indexed 0..boards-1; a board without squares
// keeps zero nuisance), `degree` polynomial terms (0: v = 1).
Fit fit_model(const std::vector<Square>& sq, int boards, int degree) {
  const int p = degree + 3 * boards;
  Fit f;
  f.nuisance.assign(std::size_t(3 * boards), 0.0);
  std::vector<double> w(sq.size(), 1.0), e(sq.size(), 0.0);
  Eigen::MatrixXd jtj;
  double sigma = 1;
  for (int it = 0; it < 25; ++it) {
    jtj = Eigen::MatrixXd::Zero(p, p);
    Eigen::VectorXd jte = Eigen::VectorXd::Zero(p);
    for (std::size_t s = 0; s < sq.size(); ++s) {
      const Square& q = sq[s];
      const double v = std::max(kMinV, poly(f.k, q.r2));
      const double* nu = &f.nuisance[std::size_t(3 * q.board)];
      e[s] = q.ln_y - nu[0] - nu[1] * q.x - nu[2] * q.y - std::log(v);
      Eigen::VectorXd j = Eigen::VectorXd::Zero(p);
      double rp = q.r2;
      for (int m = 0; m < degree; ++m, rp *= q.r2) j[m] = -rp / v;
      j[degree + 3 * q.board] = -1, j[degree + 3 * q.board + 1] = -q.x, j[degree + 3 * q.board + 2] = -q.y;
      jtj += w[s] * j * j.transpose();
      jte += w[s] * j * e[s];
    }
    jtj.diagonal().array() += 1e-9;
    const Eigen::VectorXd step = jtj.ldlt().solve(-jte);
    if (!step.allFinite()) break;
    for (int m = 0; m < degree; ++m) f.k[std::size_t(m)] += step[m];
    for (int q = 0; q < 3 * boards; ++q) f.nuisance[std::size_t(q)] += step[degree + q];
    // Huber weights at 1.345 robust sigmas.
    std::vector<double> a;
    for (std::size_t s = 0; s < sq.size(); ++s) {
      const Square& q = sq[s];
      const double* nu = &f.nuisance[std::size_t(3 * q.board)];
      e[s] = q.ln_y - nu[0] - nu[1] * q.x - nu[2] * q.y - std::log(std::max(kMinV, poly(f.k, q.r2)));
      a.push_back(std::abs(e[s]));
    }
    sigma = std::max(1.4826 * median_of(a), 1e-5);
    for (std::size_t s = 0; s < sq.size(); ++s) {
      const double t = std::abs(e[s]) / (1.345 * sigma);
      w[s] = t <= 1 ? 1.0 : 1.0 / t;
    }
    if (step.norm() < 1e-10) break;
  }
  double sw = 0, swe = 0;
  for (std::size_t s = 0; s < sq.size(); ++s) sw += w[s], swe += w[s] * e[s] * e[s];
  f.rms = sw > 0 ? std::sqrt(swe / sw) : 0;
  if (degree > 0 && int(sq.size()) > p) {
    const double s2 = swe / double(int(sq.size()) - p);
    const Eigen::MatrixXd cov = s2 * jtj.inverse();
    double var = 0;  // d v(1) = sum dk_m
    for (int a = 0; a < degree; ++a)
      for (int b = 0; b < degree; ++b) var += cov(a, b);
    const double v1 = std::max(kMinV, poly(f.k, 1.0));
    f.sigma_corner = std::sqrt(std::max(0.0, var)) / (v1 * std::log(2.0));
  }
  return f;
}

// RMS of board h's squares with v from the other boards and h's own level and gradient fitted.
double held_out_sum2(const std::vector<Square>& sq, int boards, int degree, int h, int* count) {
  std::vector<Square> rest, mine;
  for (const Square& q : sq) (q.board == h ? mine : rest).push_back(q);
  if (mine.size() < 4) return 0;
  const Fit f = fit_model(rest, boards, degree);
  // Own level and gradient: linear least squares on ln y - ln v.
  Eigen::MatrixXd a(int(mine.size()), 3);
  Eigen::VectorXd b(int(mine.size()));
  for (std::size_t s = 0; s < mine.size(); ++s) {
    a.row(int(s)) << 1, mine[s].x, mine[s].y;
    b[int(s)] = mine[s].ln_y - std::log(std::max(kMinV, poly(f.k, mine[s].r2)));
  }
  const Eigen::VectorXd x = a.colPivHouseholderQr().solve(b);
  const Eigen::VectorXd r = a * x - b;
  *count += int(mine.size());
  return r.squaredNorm();
}

}  // namespace

double Vignetting::at(double x, double y) const {
  const double r2 = ((x - centre.x()) * (x - centre.x()) + (y - centre.y()) * (y - centre.y())) / (r_corner * r_corner);
  return std::max(kMinV, poly(k, r2));
}

double Vignetting::corner_stops() const { return -std::log2(std::max(kMinV, poly(k, 1.0))); }

double vignetting_corner_radius(int width, int height, const Vec2& c) {
  double r2 = 0;
  for (const Vec2& q :
       {Vec2(-0.5, -0.5), Vec2(width - 0.5, -0.5), Vec2(-0.5, height - 0.5), Vec2(width - 0.5, height - 0.5)})
    r2 = std::max(r2, (q - c).squaredNorm());
  return std::sqrt(r2);
}

Vignetting Vignetting::none(int width, int height, const Vec2& c) {
  Vignetting v;
  v.centre = c;
  v.r_corner = vignetting_corner_radius(width, height, c);
  return v;
}

VignettingEstimate estimate_vignetting(const std::vector<VignettingBoard>& boards, const ResponseCurve& curve,
                                       const Vec2& centre, int width, int height) {
  VignettingEstimate est;
  est.model = Vignetting::none(width, height, centre);
  const double rc = est.model.r_corner;
  std::vector<Square> sq;
  int used = 0;
  for (const VignettingBoard& b : boards) {
    if (b.codes.type() != CV_16UC3) throw std::invalid_argument(b.name + ": board codes must be CV_16UC3");
    if (b.gridn < 2 || int(b.corners.size()) != b.gridn * b.gridn)
      throw std::invalid_argument(b.name + ": expected " + std::to_string(b.gridn * b.gridn) + " corners");
    if (b.codes.cols != width || b.codes.rows != height) continue;
    VignettingBoard scaled = b;
    if (curve.max_code == 65535) {
      double mx;
      cv::minMaxLoc(b.codes.reshape(1), nullptr, &mx);
      if (mx <= 255) b.codes.convertTo(scaled.codes, CV_16UC3, 257);  // an 8-bit board read against a 16-bit curve
    }
    std::vector<Square> s = board_squares(scaled, used, curve, centre, rc);
    if (s.size() < 6) continue;
    sq.insert(sq.end(), s.begin(), s.end());
    ++used;
  }
  est.boards = used;
  est.squares = int(sq.size());
  if (used < 3) {
    est.note = "white squares measured on " + std::to_string(used) + " board(s); need at least 3";
    return est;
  }
  for (const Square& q : sq) est.max_r = std::max(est.max_r, std::sqrt(q.r2));
  // Degree by leave-one-board-out error.
  int best = 1;
  double best_err = 0;
  for (int d = 1; d <= 3; ++d) {
    double s2 = 0;
    int count = 0;
    for (int h = 0; h < used; ++h) s2 += held_out_sum2(sq, used, d, h, &count);
    est.held_out_rms[std::size_t(d - 1)] = count > 0 ? std::sqrt(s2 / count) : 0;
    if (d == 1 || est.held_out_rms[std::size_t(d - 1)] < 0.98 * best_err)
      best = d, best_err = est.held_out_rms[std::size_t(d - 1)];
  }
  const Fit f = fit_model(sq, used, best);
  est.degree = best;
  est.model.k = f.k;
  est.model.source = "chessboards";
  est.rms = f.rms;
  est.corner_sigma_stops = f.sigma_corner;
  return est;
}

cv::Mat read_board_codes(const std::filesystem::path& file) {
  if (is_raw_file(file)) return read_raw_image(file).codes;  // linear, as the RAW brackets
  cv::Mat img = read_image(file.string(), cv::IMREAD_UNCHANGED | cv::IMREAD_ANYDEPTH);
  if (img.empty()) throw std::runtime_error(file.string() + ": cannot read the image");
  if (img.depth() != CV_8U && img.depth() != CV_16U)
    throw std::runtime_error(file.string() + ": expected 8 or 16 bits");
  cv::Mat rgb;
  if (img.channels() == 1)
    cv::cvtColor(img, rgb, cv::COLOR_GRAY2RGB);
  else if (img.channels() == 3)
    cv::cvtColor(img, rgb, cv::COLOR_BGR2RGB);
  else if (img.channels() == 4)
    cv::cvtColor(img, rgb, cv::COLOR_BGRA2RGB);
  else
    throw std::runtime_error(file.string() + ": unsupported channel count");
  cv::Mat out;
  rgb.convertTo(out, CV_16UC3);
  return out;
}

void divide_vignetting(MergedImage& image, const Vignetting& v) {
  if (v.is_identity()) return;
  for (int y = 0; y < image.radiance.rows; ++y) {
    auto* r = image.radiance.ptr<cv::Vec3f>(y);
    auto* var = image.variance.empty() ? nullptr : image.variance.ptr<cv::Vec3f>(y);
    for (int x = 0; x < image.radiance.cols; ++x) {
      const float inv = float(1.0 / v.at(x, y));
      r[x] *= inv;
      if (var) var[x] *= inv * inv;
    }
  }
}

nlohmann::json vignetting_json(const Vignetting& v) {
  return {{"model", "pa"},
          {"formula", "v = 1 + k1 r^2 + k2 r^4 + k3 r^6, r = |p - centre| / r_corner"},
          {"centre_px", {v.centre.x(), v.centre.y()}},
          {"r_corner_px", v.r_corner},
          {"k", v.k},
          {"corner_stops", v.corner_stops()},
          {"source", v.source}};
}

Vignetting vignetting_from_json(const nlohmann::json& j, const std::string& what) {
  try {
    Vignetting v;
    if (j.at("model").get<std::string>() != "pa") throw std::invalid_argument("model: expected \"pa\"");
    const auto c = j.at("centre_px");
    v.centre = Vec2(c.at(0).get<double>(), c.at(1).get<double>());
    v.r_corner = j.at("r_corner_px").get<double>();
    const auto k = j.at("k");
    if (!k.is_array() || k.size() != 3) throw std::invalid_argument("k: expected 3 numbers");
    for (int i = 0; i < 3; ++i) v.k[std::size_t(i)] = k.at(std::size_t(i)).get<double>();
    v.source = j.value("source", "given");
    if (!v.centre.allFinite() || !(v.r_corner > 0) || !std::isfinite(v.k[0] + v.k[1] + v.k[2]))
      throw std::invalid_argument("non-finite or non-positive values");
    for (int i = 0; i <= 20; ++i)
      if (!(poly(v.k, i / 20.0) > kMinV))
        throw std::invalid_argument("the polynomial falls below 0.05 inside the image");
    return v;
  } catch (const nlohmann::json::exception& e) {
    throw std::invalid_argument(
        what + ": not a vignetting model ({model: pa, centre_px, r_corner_px, k}): " + json_error_text(e));
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(what + ": " + e.what());
  }
}

}  // namespace rsibr
