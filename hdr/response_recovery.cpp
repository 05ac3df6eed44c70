#include "hdr/response_recovery.h"

#include "hdr/nnls.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>

namespace rsibr {
namespace {

constexpr int kKnots = 256;
constexpr double kInf = std::numeric_limits<double>::infinity();

bool usable(const ResponseSamples& s, int z) { return z >= s.low_code && z < s.saturation_code; }

// Indices of brackets usable in channel c for sample i.
std::vector<int> usable_brackets(const ResponseSamples& s, std::size_t i, int c) {
  std::vector<int> out;
  for (std::size_t j = 0; j < s.codes[i].size(); ++j)
    if (usable(s, s.codes[i][j][std::size_t(c)])) out.push_back(int(j));
  return out;
}

// Debevec's hat on [0, max_code], with a floor so the end knots stay determined.
double hat(double z, int max_code) {
  const double u = z / max_code;
  return std::max(0.02, 1.0 - std::abs(2.0 * u - 1.0));
}

ResponseCurve fit_gamma(const ResponseSamples& s, const std::vector<double>& e) {
  std::array<double, 3> gamma{};
  for (int c = 0; c < 3; ++c) {
    double num = 0, den = 0;
    for (std::size_t i = 0; i < s.codes.size(); ++i) {
      if (s.held_out[i]) continue;
      const auto v = usable_brackets(s, i, c);
      for (std::size_t a = 1; a < v.size(); ++a) {
        const double du = std::log(double(s.codes[i][std::size_t(v[a])][std::size_t(c)])) -
                          std::log(double(s.codes[i][std::size_t(v[a - 1])][std::size_t(c)]));
        const double de = std::log(e[std::size_t(v[a])]) - std::log(e[std::size_t(v[a - 1])]);
        num += du * de, den += du * du;
      }
    }
    gamma[std::size_t(c)] = den > 0 ? num / den : 1.0;
    if (!(gamma[std::size_t(c)] > 0.05 && gamma[std::size_t(c)] < 20)) gamma[std::size_t(c)] = 1.0;
  }
  const int knots = s.max_code == 255 ? 256 : 1024;
  ResponseCurve r = ResponseCurve::sampled("gamma", s.max_code, knots,
                                           [&](int c, double u) { return std::pow(u, gamma[std::size_t(c)]); });
  r.parameters = {{"gamma", gamma}};
  return r;
}

ResponseCurve fit_polynomial(const ResponseSamples& s, const std::vector<double>& e, int degree) {
  // X(u) = u^d + sum_{n<d} c_n (u^n - u^d); rows (X(u_j)/e_j - X(u_k)/e_k) * scale = 0.
  std::array<std::vector<double>, 3> coeffs;
  for (int c = 0; c < 3; ++c) {
    std::vector<std::array<double, 8>> rows;
    std::vector<double> rhs;
    for (std::size_t i = 0; i < s.codes.size(); ++i) {
      if (s.held_out[i]) continue;
      const auto v = usable_brackets(s, i, c);
      for (std::size_t a = 1; a < v.size(); ++a) {
        const double uj = double(s.codes[i][std::size_t(v[a - 1])][std::size_t(c)]) / s.max_code;
        const double uk = double(s.codes[i][std::size_t(v[a])][std::size_t(c)]) / s.max_code;
        const double ej = e[std::size_t(v[a - 1])], ek = e[std::size_t(v[a])];
        const double scale = 1.0 / (uj / ej + uk / ek);
        std::array<double, 8> row{};
        for (int n = 1; n < degree; ++n)
          row[std::size_t(n - 1)] = ((std::pow(uj, n) - std::pow(uj, degree)) / ej - (std::pow(uk, n) - std::pow(uk, degree)) / ek) * scale;
        rows.push_back(row);
        rhs.push_back(-(std::pow(uj, degree) / ej - std::pow(uk, degree) / ek) * scale);
      }
    }
    Eigen::MatrixXd A(int(rows.size()), degree - 1);
    Eigen::VectorXd b(int(rows.size()));
    for (int r = 0; r < int(rows.size()); ++r) {
      for (int n = 0; n < degree - 1; ++n) A(r, n) = rows[std::size_t(r)][std::size_t(n)];
      b(r) = rhs[std::size_t(r)];
    }
    const Eigen::VectorXd x = rows.empty() ? Eigen::VectorXd::Zero(degree - 1) : Eigen::VectorXd(A.colPivHouseholderQr().solve(b));
    auto& cf = coeffs[std::size_t(c)];
    cf.assign(std::size_t(degree), 0.0);
    double rest = 1.0;
    for (int n = 0; n < degree - 1; ++n) cf[std::size_t(n)] = x(n), rest -= x(n);
    cf[std::size_t(degree - 1)] = rest;
  }
  const int knots = s.max_code == 255 ? 256 : 1024;
  ResponseCurve r = ResponseCurve::sampled("polynomial", s.max_code, knots, [&](int c, double u) {
    double x = 0, p = 1;
    for (double k : coeffs[std::size_t(c)]) p *= u, x += k * p;
    return std::max(0.0, x);  // a slightly negative fit next to code 0 is black
  });
  r.parameters = {{"degree", degree}, {"coefficients", coeffs}};
  return r;
}

int knot_of(int z, int max_code) { return int(std::lround(double(z) * (kKnots - 1) / max_code)); }

// Isotonic regression (pool adjacent violators): the non-decreasing sequence nearest to x in
// weighted least squares.
void pool_adjacent_violators(std::vector<double>& x, const std::vector<double>& w) {
  struct Block { double value, weight; std::size_t size; };
  std::vector<Block> blocks;
  for (std::size_t i = 0; i < x.size(); ++i) {
    blocks.push_back({x[i], std::max(w[i], 1e-12), 1});
    while (blocks.size() > 1 && blocks[blocks.size() - 2].value > blocks.back().value) {
      const Block b = blocks.back();
      blocks.pop_back();
      Block& a = blocks.back();
      a.value = (a.value * a.weight + b.value * b.weight) / (a.weight + b.weight);
      a.weight += b.weight;
      a.size += b.size;
    }
  }
  std::size_t i = 0;
  for (const Block& b : blocks)
    for (std::size_t k = 0; k < b.size; ++k) x[i++] = b.value;
}

// Fills knots without data by linear interpolation (constant extrapolation at the ends), then
// makes the curve non-decreasing and positive, and normalises the top knot to 1.
void finish_knots(std::vector<double>& x, const std::vector<bool>& has, const std::vector<double>& weight) {
  pool_adjacent_violators(x, weight);
  const int n = int(x.size());
  int prev = -1;
  for (int k = 0; k < n; ++k) {
    if (!has[std::size_t(k)]) continue;
    if (prev < 0)
      for (int m = 0; m < k; ++m) x[std::size_t(m)] = x[std::size_t(k)] * double(m) / std::max(1, k);
    else
      for (int m = prev + 1; m < k; ++m)
        x[std::size_t(m)] = x[std::size_t(prev)] + (x[std::size_t(k)] - x[std::size_t(prev)]) * double(m - prev) / (k - prev);
    prev = k;
  }
  if (prev < 0) throw std::runtime_error("no usable samples in a channel");
  // Above the last filled knot: continue the last slope (saturation never has data).
  const double slope = prev > 0 ? std::max(0.0, x[std::size_t(prev)] - x[std::size_t(prev - 1)]) : 0.0;
  for (int m = prev + 1; m < n; ++m) x[std::size_t(m)] = x[std::size_t(prev)] + slope * (m - prev);
  const double top = x.back();
  if (!(top > 0)) throw std::runtime_error("degenerate response (flat)");
  for (double& v : x) v = std::max(0.0, v / top);
}

ResponseCurve fit_robertson(const ResponseSamples& s, const std::vector<double>& e) {
  ResponseCurve r;
  r.model = "robertson";
  r.max_code = s.max_code;
  const int iterations = 30;
  for (int c = 0; c < 3; ++c) {
    std::vector<double> x(kKnots);
    for (int k = 0; k < kKnots; ++k) x[std::size_t(k)] = double(k) / (kKnots - 1);
    auto weight = [&](int k) { const double d = (k - 127.5) / 127.5; return std::exp(-4.0 * d * d); };
    std::vector<double> sum(kKnots), count(kKnots);
    std::vector<bool> has(kKnots, false);
    for (int it = 0; it < iterations; ++it) {
      std::fill(sum.begin(), sum.end(), 0.0);
      std::fill(count.begin(), count.end(), 0.0);
      for (std::size_t i = 0; i < s.codes.size(); ++i) {
        if (s.held_out[i]) continue;
        const auto v = usable_brackets(s, i, c);
        if (v.size() < 2) continue;
        double num = 0, den = 0;
        for (int j : v) {
          const int k = knot_of(s.codes[i][std::size_t(j)][std::size_t(c)], s.max_code);
          num += weight(k) * e[std::size_t(j)] * x[std::size_t(k)];
          den += weight(k) * e[std::size_t(j)] * e[std::size_t(j)];
        }
        const double L = num / den;
        for (int j : v) {
          const int k = knot_of(s.codes[i][std::size_t(j)][std::size_t(c)], s.max_code);
          sum[std::size_t(k)] += L * e[std::size_t(j)];
          count[std::size_t(k)] += 1;
        }
      }
      for (int k = 0; k < kKnots; ++k) {
        has[std::size_t(k)] = count[std::size_t(k)] > 0;
        if (has[std::size_t(k)]) x[std::size_t(k)] = sum[std::size_t(k)] / count[std::size_t(k)];
      }
      finish_knots(x, has, count);
    }
    r.knots[std::size_t(c)] = x;
  }
  r.parameters = {{"iterations", iterations}, {"bins", kKnots}};
  return r;
}

ResponseCurve fit_debevec(const ResponseSamples& s, const std::vector<double>& e, double smoothness) {
  ResponseCurve r;
  r.model = "debevec";
  r.max_code = s.max_code;
  const int K = kKnots;
  const int mid = K / 2;
  // g = T delta: g_k = sum_{m<k} delta_m - sum_{m<mid} delta_m (so g_mid = 0), delta >= 0.
  Eigen::MatrixXd T = Eigen::MatrixXd::Zero(K, K - 1);
  for (int k = 0; k < K; ++k)
    for (int m = 0; m < K - 1; ++m) T(k, m) = (m < k ? 1.0 : 0.0) - (m < mid ? 1.0 : 0.0);
  for (int c = 0; c < 3; ++c) {
    Eigen::MatrixXd H = Eigen::MatrixXd::Zero(K, K);
    Eigen::VectorXd h = Eigen::VectorXd::Zero(K);
    std::vector<bool> has(std::size_t(K), false);
    long data_rows = 0;
    for (std::size_t i = 0; i < s.codes.size(); ++i) {
      if (s.held_out[i]) continue;
      const auto v = usable_brackets(s, i, c);
      if (v.size() < 2) continue;
      // Interpolation of g at each code: (knot, weight) pairs; hat weights; a_j = w_j^2 / sum w^2.
      struct Term { int k0; double f, w, lne; };
      std::vector<Term> t;
      double wsum = 0;
      for (int j : v) {
        const double z = s.codes[i][std::size_t(j)][std::size_t(c)];
        const double pos = z * (K - 1) / s.max_code;
        const int k0 = std::min(int(pos), K - 2);
        t.push_back({k0, pos - k0, hat(z, s.max_code), std::log(e[std::size_t(j)])});
        wsum += t.back().w * t.back().w;
        has[std::size_t(k0)] = has[std::size_t(k0 + 1)] = true;
      }
      double mean_lne = 0;
      for (const Term& a : t) mean_lne += a.w * a.w / wsum * a.lne;
      // Row j: w_j (phi_j - sum_k a_k phi_k) . g = w_j (ln e_j - sum_k a_k ln e_k).
      for (const Term& a : t) {
        std::vector<std::pair<int, double>> row;
        row.push_back({a.k0, a.w * (1 - a.f)});
        row.push_back({a.k0 + 1, a.w * a.f});
        for (const Term& b : t) {
          const double ak = b.w * b.w / wsum;
          row.push_back({b.k0, -a.w * ak * (1 - b.f)});
          row.push_back({b.k0 + 1, -a.w * ak * b.f});
        }
        const double rhs = a.w * (a.lne - mean_lne);
        for (const auto& [p, vp] : row) {
          h(p) += vp * rhs;
          for (const auto& [q, vq] : row) H(p, q) += vp * vq;
        }
        ++data_rows;
      }
    }
    if (data_rows == 0) throw std::runtime_error("no usable samples in channel " + std::to_string(c));
    // Smoothness: lambda * (data rows per knot) * w(k)^2 (g_{k-1} - 2 g_k + g_{k+1})^2.
    const double lambda = smoothness * double(data_rows) / K;
    for (int k = 1; k < K - 1; ++k) {
      const double w = hat(double(k) * s.max_code / (K - 1), s.max_code);
      const double l = lambda * w * w;
      const int idx[3] = {k - 1, k, k + 1};
      const double cf[3] = {1, -2, 1};
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) H(idx[a], idx[b]) += l * cf[a] * cf[b];
    }
    Eigen::MatrixXd Q = T.transpose() * H * T;
    Q.diagonal().array() += 1e-12 * Q.diagonal().maxCoeff();
    const Eigen::VectorXd p = T.transpose() * h;
    const Eigen::VectorXd delta = nnls_gram(Q, p);
    const Eigen::VectorXd g = T * delta;
    std::vector<double> x(static_cast<std::size_t>(K));
    for (int k = 0; k < K; ++k) x[std::size_t(k)] = std::exp(g(k) - g(K - 1));
    r.knots[std::size_t(c)] = x;
  }
  r.parameters = {{"lambda", smoothness}, {"knots", K}};
  return r;
}

}  // namespace

int default_saturation_code(int max_code) { return max_code - max_code / 200; }

ResponseSamples select_samples(const BracketSet& b, const RecoveryOptions& o) {
  ResponseSamples s;
  s.max_code = b.max_code;
  s.low_code = std::max(1, b.max_code / 20);
  s.saturation_code = o.saturation_code > 0 ? o.saturation_code : default_saturation_code(b.max_code);
  if (b.size() < 2) throw std::runtime_error("one bracket: a response cannot be recovered (give --response or --model identity)");
  const int P = int(b.size()), H = b.rows(), W = b.cols();
  const int stride = std::max(1, int(std::sqrt(double(H) * W / 40000.0)));
  struct Candidate { int r, c; double proxy, roughness; };
  std::vector<Candidate> cand;
  const int border = 2;
  for (int r = border + stride / 2; r < H - border; r += stride) {
    for (int c = border + stride / 2; c < W - border; c += stride) {
      // Codes must not decrease with exposure (else: motion); pick the best-exposed bracket.
      bool monotone = true, any_usable = false;
      int best = -1;
      double best_d = kInf;
      for (int j = 0; j < P; ++j) {
        const auto z = b.codes[std::size_t(j)].at<cv::Vec3w>(r, c);
        bool ok = true;
        double mean = 0;
        for (int ch = 0; ch < 3; ++ch) {
          ok = ok && usable(s, z[ch]);
          mean += z[ch] / 3.0;
          if (j > 0 && z[ch] + b.max_code / 50 < b.codes[std::size_t(j - 1)].at<cv::Vec3w>(r, c)[ch]) monotone = false;
        }
        if (ok) any_usable = true;
        const double d = std::abs(mean - 0.5 * b.max_code);
        if (ok && d < best_d) best_d = d, best = j;
      }
      if (!monotone || !any_usable) continue;
      const cv::Mat& img = b.codes[std::size_t(best)];
      double sum[3] = {0, 0, 0}, sq[3] = {0, 0, 0}, mean = 0;
      for (int dr = -2; dr <= 2; ++dr)
        for (int dc = -2; dc <= 2; ++dc) {
          const auto z = img.at<cv::Vec3w>(r + dr, c + dc);
          for (int ch = 0; ch < 3; ++ch) sum[ch] += z[ch], sq[ch] += double(z[ch]) * z[ch];
        }
      double rough = 0;
      for (int ch = 0; ch < 3; ++ch) {
        const double m = sum[ch] / 25;
        rough += std::sqrt(std::max(0.0, sq[ch] / 25 - m * m));
        mean += m / 3;
      }
      cand.push_back({r, c, std::log((mean + 1) / b.max_code) - std::log(b.exposures[std::size_t(best)]), rough / b.max_code});
    }
  }
  if (cand.size() < 20)
    throw std::runtime_error("too few usable pixels for response recovery (every pixel saturated or black in every bracket?)");
  // Reject the roughest quarter, then balance across 64 bins of the log-radiance proxy, keeping
  // the smoothest pixels of each bin (ties: raster order).
  std::vector<double> rough(cand.size());
  for (std::size_t i = 0; i < cand.size(); ++i) rough[i] = cand[i].roughness;
  std::nth_element(rough.begin(), rough.begin() + long(rough.size() * 3 / 4), rough.end());
  const double rough_limit = rough[rough.size() * 3 / 4];
  double lo = kInf, hi = -kInf;
  for (const auto& k : cand) lo = std::min(lo, k.proxy), hi = std::max(hi, k.proxy);
  const int bins = 64;
  std::vector<std::vector<std::size_t>> binned(bins);
  for (std::size_t i = 0; i < cand.size(); ++i) {
    if (cand[i].roughness > rough_limit) continue;
    const int k = hi > lo ? std::min(bins - 1, int((cand[i].proxy - lo) / (hi - lo) * bins)) : 0;
    binned[std::size_t(k)].push_back(i);
  }
  const std::size_t quota = std::size_t(std::max(2, o.samples / bins));
  std::vector<std::size_t> chosen;
  for (auto& bin : binned) {
    std::stable_sort(bin.begin(), bin.end(), [&](std::size_t a, std::size_t c) { return cand[a].roughness < cand[c].roughness; });
    for (std::size_t m = 0; m < std::min(quota, bin.size()); ++m) chosen.push_back(bin[m]);
  }
  std::stable_sort(chosen.begin(), chosen.end(), [&](std::size_t a, std::size_t c) { return cand[a].proxy < cand[c].proxy; });
  for (std::size_t n = 0; n < chosen.size(); ++n) {
    const Candidate& k = cand[chosen[n]];
    std::vector<std::array<int, 3>> codes;
    for (int j = 0; j < P; ++j) {
      const auto z = b.codes[std::size_t(j)].at<cv::Vec3w>(k.r, k.c);
      codes.push_back({z[0], z[1], z[2]});
    }
    s.codes.push_back(codes);
    s.held_out.push_back(n % 2 == 1);
  }
  if (s.codes.size() < 20) throw std::runtime_error("too few usable pixels for response recovery");
  return s;
}

ResponseCurve fit_response(const std::string& model, const ResponseSamples& s, const std::vector<double>& e,
                           const RecoveryOptions& o) {
  if (model == "identity") return ResponseCurve::identity(s.max_code);
  if (model == "gamma") return fit_gamma(s, e);
  if (model.rfind("polynomial:", 0) == 0) return fit_polynomial(s, e, std::stoi(model.substr(11)));
  if (model == "robertson") return fit_robertson(s, e);
  if (model == "debevec") return fit_debevec(s, e, o.smoothness);
  throw std::invalid_argument("unknown response model '" + model + "' (identity, gamma, polynomial, robertson, debevec)");
}

double held_out_error(const ResponseCurve& curve, const ResponseSamples& s, const std::vector<double>& e) {
  // Predict codes: the radiance seen by a pixel's best-exposed usable bracket (code nearest the
  // middle), times e_j, through the inverse of the curve, against the codes observed in its other
  // usable brackets. Errors are in code units (noise there is roughly even across the range and
  // symmetric, so no curve can win by bending toward a noise bias as a log-space fit could).
  double total = 0;
  long count = 0;
  for (std::size_t i = 0; i < s.codes.size(); ++i) {
    if (!s.held_out[i]) continue;
    for (int c = 0; c < 3; ++c) {
      const auto v = usable_brackets(s, i, c);
      if (v.size() < 2) continue;
      int ref = v[0];
      for (int j : v)
        if (std::abs(s.codes[i][std::size_t(j)][std::size_t(c)] - s.max_code / 2) <
            std::abs(s.codes[i][std::size_t(ref)][std::size_t(c)] - s.max_code / 2))
          ref = j;
      const double L = curve.linear(c, s.codes[i][std::size_t(ref)][std::size_t(c)]) / e[std::size_t(ref)];
      for (int j : v) {
        if (j == ref) continue;
        const double d = (curve.code(c, L * e[std::size_t(j)]) - s.codes[i][std::size_t(j)][std::size_t(c)]) / s.max_code;
        total += d * d;
        ++count;
      }
    }
  }
  return count > 0 ? std::sqrt(total / double(count)) : kInf;
}

ResponseRecovery recover_response(const BracketSet& b, const RecoveryOptions& o) {
  const ResponseSamples s = select_samples(b, o);
  ResponseRecovery out;
  for (bool h : s.held_out) (h ? out.held_out_samples : out.train_samples)++;
  struct Entry { std::string fit_name, family; int complexity; };
  std::vector<Entry> entries = {{"identity", "identity", 0}, {"gamma", "gamma", 1}};
  for (int d = 2; d <= 5; ++d) entries.push_back({"polynomial:" + std::to_string(d), "polynomial", d - 1});
  entries.push_back({"robertson", "robertson", kKnots});
  entries.push_back({"debevec", "debevec", kKnots});
  std::vector<ResponseCurve> curves;
  for (const Entry& en : entries) {
    if (o.model != "auto" && o.model != en.family) continue;
    ResponseCurve curve = fit_response(en.fit_name, s, b.exposures, o);
    ModelCandidate cand{en.family, en.complexity, held_out_error(curve, s, b.exposures), curve.parameters};
    try {
      curve.validate();
    } catch (const std::invalid_argument&) {
      cand.held_out_error = kInf;  // e.g. a non-monotone polynomial
    }
    out.candidates.push_back(cand);
    curves.push_back(std::move(curve));
  }
  if (out.candidates.empty())
    throw std::invalid_argument("unknown response model '" + o.model + "' (auto, identity, gamma, polynomial, robertson, debevec)");
  double best = kInf;
  for (const auto& c : out.candidates) best = std::min(best, c.held_out_error);
  if (!std::isfinite(best)) throw std::runtime_error("no response model fits these brackets (is the exposure data right?)");
  for (std::size_t k = 0; k < out.candidates.size(); ++k)
    if (out.candidates[k].held_out_error <= best * 1.05) {
      out.curve = curves[k];
      break;
    }
  return out;
}

}  // namespace rsibr
