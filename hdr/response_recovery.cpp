#include "hdr/response_recovery.h"

#include "hdr/nnls.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <sstream>
#include <stdexcept>

namespace rsibr {
namespace {

constexpr int kKnots = 256;
constexpr double kInf = std::numeric_limits<double>::infinity();

// One channel of one sample pixel: its usable brackets' codes and exposures (ascending exposure).
struct Track {
  int sample = 0, channel = 0;
  std::vector<std::pair<int, double>> obs;  // (code, exposure)
};

bool usable(const ResponseSamples& s, std::size_t i, std::size_t j, int c) {
  const int z = s.codes[i][j][std::size_t(c)];
  return int(j) < s.saturated_from[i] && z >= s.low_code && z < s.saturation[std::size_t(c)];
}

// Usable and above the near-black codes (max_code / 20): what the held-out error scores. Near
// black, rounding, read noise and the black clip make E[code | X] differ from the curve, and a
// flexible model would be rewarded for imitating that instead of the camera.
bool scored(const ResponseSamples& s, std::size_t i, std::size_t j, int c) {
  return usable(s, i, j, c) && s.codes[i][j][std::size_t(c)] >= std::max(1, s.max_code / 20);
}

// Tracks with at least two usable brackets at or above min_code: the training or the held-out half,
// channel c (-1: all).
std::vector<Track> make_tracks(const ResponseSamples& s, bool held_out, int channel, int min_code = 0) {
  std::vector<Track> out;
  for (std::size_t i = 0; i < s.codes.size(); ++i) {
    if (s.held_out[i] != held_out) continue;
    const auto& e = s.exposures[std::size_t(s.view[i])];
    for (int c = 0; c < 3; ++c) {
      if (channel >= 0 && c != channel) continue;
      Track t;
      t.sample = int(i), t.channel = c;
      for (std::size_t j = 0; j < s.codes[i].size(); ++j)
        if (usable(s, i, j, c) && s.codes[i][j][std::size_t(c)] >= min_code)
          t.obs.push_back({s.codes[i][j][std::size_t(c)], e[j]});
      if (t.obs.size() >= 2) out.push_back(std::move(t));
    }
  }
  return out;
}

// Debevec's hat on [0, max_code], with a floor so the end knots stay determined.
double hat(double z, int max_code) {
  const double u = z / max_code;
  return std::max(0.02, 1.0 - std::abs(2.0 * u - 1.0));
}

int parametric_knots(int max_code) { return max_code == 255 ? 256 : 1024; }

// X(u) sampled at `count` knots uniformly in u.
template <class F>
std::vector<double> sample_knots(int count, F&& f) {
  std::vector<double> x(static_cast<std::size_t>(count));
  for (int k = 0; k < count; ++k) x[std::size_t(k)] = f(double(k) / (count - 1));
  return x;
}

// Weight of a pair of codes in the gamma fit: 1 / var(ln z_j - ln z_k) for an error of constant
// size in code (quantisation, noise), so the low codes' large errors in ln z do not lead.
double pair_weight(int zj, int zk) { return 1.0 / (1.0 / (double(zj) * zj) + 1.0 / (double(zk) * zk)); }

double fit_gamma(const std::vector<Track>& tracks, int max_code) {
  double num = 0, den = 0;
  for (const Track& t : tracks)
    for (std::size_t a = 1; a < t.obs.size(); ++a) {
      const double du = std::log(double(t.obs[a].first) / max_code) - std::log(double(t.obs[a - 1].first) / max_code);
      const double de = std::log(t.obs[a].second) - std::log(t.obs[a - 1].second);
      const double w = pair_weight(t.obs[a].first, t.obs[a - 1].first);
      num += w * du * de, den += w * du * du;
    }
  const double g = den > 0 ? num / den : 1.0;
  return g > 0.05 && g < 20 ? g : 1.0;
}

std::vector<double> fit_polynomial(const std::vector<Track>& tracks, int max_code, int degree) {
  // X(u) = u^d + sum_{n<d} c_n (u^n - u^d); rows (X(u_j)/e_j - X(u_k)/e_k) * scale = 0.
  std::vector<std::array<double, 8>> rows;
  std::vector<double> rhs;
  for (const Track& t : tracks)
    for (std::size_t a = 1; a < t.obs.size(); ++a) {
      const double uj = double(t.obs[a - 1].first) / max_code, uk = double(t.obs[a].first) / max_code;
      const double ej = t.obs[a - 1].second, ek = t.obs[a].second;
      const double scale = 1.0 / (uj / ej + uk / ek);
      std::array<double, 8> row{};
      for (int n = 1; n < degree; ++n)
        row[std::size_t(n - 1)] =
            ((std::pow(uj, n) - std::pow(uj, degree)) / ej - (std::pow(uk, n) - std::pow(uk, degree)) / ek) * scale;
      rows.push_back(row);
      rhs.push_back(-(std::pow(uj, degree) / ej - std::pow(uk, degree) / ek) * scale);
    }
  Eigen::MatrixXd A(int(rows.size()), degree - 1);
  Eigen::VectorXd b(int(rows.size()));
  for (int r = 0; r < int(rows.size()); ++r) {
    for (int n = 0; n < degree - 1; ++n) A(r, n) = rows[std::size_t(r)][std::size_t(n)];
    b(r) = rhs[std::size_t(r)];
  }
  const Eigen::VectorXd x =
      rows.empty() ? Eigen::VectorXd::Zero(degree - 1) : Eigen::VectorXd(A.colPivHouseholderQr().solve(b));
  std::vector<double> cf(std::size_t(degree), 0.0);
  double rest = 1.0;
  for (int n = 0; n < degree - 1; ++n) cf[std::size_t(n)] = x(n), rest -= x(n);
  cf[std::size_t(degree - 1)] = rest;
  return cf;
}

double polynomial_at(const std::vector<double>& cf, double u) {
  double x = 0, p = 1;
  for (double k : cf) p *= u, x += k * p;
  return std::max(0.0, x);  // a slightly negative fit next to code 0 is black
}

double knot_position(int z, int max_code) { return double(z) * (kKnots - 1) / max_code; }

// Isotonic regression (pool adjacent violators): the non-decreasing sequence nearest to x in
// weighted least squares.
void pool_adjacent_violators(std::vector<double>& x, const std::vector<double>& w) {
  struct Block {
    double value, weight;
    std::size_t size;
  };
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

// Smoothness: sum_k lambda w(k)^2 (second derivative of g)^2, w Debevec's hat. Above the code
// z_b = max_code / 8 the derivative is the plain second difference in code; below it, toward black,
// it is taken in the log-code t = ln(z + z0) (z0 one 8-bit code), scaled to meet the plain one at
// z_b: a power law X ~ z^p (every camera's toe, sRGB's linear segment included) is straight in t,
// while ln X ~ p ln z curves without bound in z there, so a code-domain penalty bends the dark end
// (it made X several times too large at the lowest codes). On uniform knots (spacing h codes),
//   d^2g/dt^2 = (z+z0)^2 g'' + (z+z0) g' ~ (z+z0)^2 (g_{k-1} - 2 g_k + g_{k+1}) / h^2 + (z+z0) (g_{k+1} - g_{k-1}) / 2h,
// times h^2 / z_b^2.
void add_smoothness(Eigen::MatrixXd& H, double lambda, int max_code) {
  const int K = int(H.rows());
  const double h = double(max_code) / (K - 1), z0 = max_code / 255.0, zb = max_code / 8.0;
  for (int k = 1; k < K - 1; ++k) {
    const double z = k * h + z0;
    const double w = hat(double(k) * h, max_code);
    const double l = lambda * w * w;
    double cf[3] = {1, -2, 1};
    if (z < zb) {
      const double a = z * z / (zb * zb), b = z * h / (2 * zb * zb);
      cf[0] = a - b, cf[1] = -2 * a, cf[2] = a + b;
    }
    const int idx[3] = {k - 1, k, k + 1};
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) H(idx[i], idx[j]) += l * cf[i] * cf[j];
  }
}

// Robertson with each X update smoothed: the knot means m_k (counts n_k) become the g = ln X that
// minimises sum_k n_k (g_k - ln m_k)^2 + lambda' sum_k w_k^2 (second difference of g)^2 (a
// Whittaker smoother; knots without data are filled by it), then made non-decreasing.
std::vector<double> fit_robertson(const std::vector<Track>& tracks, int max_code, double smoothness) {
  const int iterations = 30;
  std::vector<double> x(kKnots);
  for (int k = 0; k < kKnots; ++k) x[std::size_t(k)] = std::max(1e-6, double(k) / (kKnots - 1));
  auto weight = [&](int k) {
    const double d = (k - 127.5) / 127.5;
    return std::exp(-4.0 * d * d);
  };
  std::vector<double> sum(kKnots), count(kKnots);
  double total = 0;
  for (const Track& t : tracks) total += double(t.obs.size());
  const double lambda = smoothness * total / kKnots;
  for (int it = 0; it < iterations; ++it) {
    std::fill(sum.begin(), sum.end(), 0.0);
    std::fill(count.begin(), count.end(), 0.0);
    for (const Track& t : tracks) {
      double num = 0, den = 0;
      for (const auto& [z, e] : t.obs) {
        const int k = int(std::lround(knot_position(z, max_code)));
        num += weight(k) * e * x[std::size_t(k)];
        den += weight(k) * e * e;
      }
      const double L = num / den;
      for (const auto& [z, e] : t.obs) {
        const int k = int(std::lround(knot_position(z, max_code)));
        sum[std::size_t(k)] += L * e;
        count[std::size_t(k)] += 1;
      }
    }
    Eigen::MatrixXd H = Eigen::MatrixXd::Zero(kKnots, kKnots);
    Eigen::VectorXd h = Eigen::VectorXd::Zero(kKnots);
    for (int k = 0; k < kKnots; ++k)
      if (count[std::size_t(k)] > 0 && sum[std::size_t(k)] > 0) {
        H(k, k) += count[std::size_t(k)];
        h(k) += count[std::size_t(k)] * std::log(sum[std::size_t(k)] / count[std::size_t(k)]);
      }
    if (!(H.diagonal().sum() > 0)) throw std::runtime_error("no usable samples in a channel");
    add_smoothness(H, lambda, max_code);
    H.diagonal().array() += 1e-9 * H.diagonal().maxCoeff();
    const Eigen::VectorXd g = H.ldlt().solve(h);
    for (int k = 0; k < kKnots; ++k) x[std::size_t(k)] = std::exp(std::clamp(g(k), -700.0, 700.0));
    pool_adjacent_violators(x, count);
    const double top = x.back();
    for (double& v : x) v = std::max(1e-300, v / top);
  }
  return x;
}

std::vector<double> fit_debevec(const std::vector<Track>& tracks, int max_code, double smoothness) {
  const int K = kKnots;
  const int mid = K / 2;
  // g = T delta: g_k = sum_{m<k} delta_m - sum_{m<mid} delta_m (so g_mid = 0), delta >= 0.
  Eigen::MatrixXd T = Eigen::MatrixXd::Zero(K, K - 1);
  for (int k = 0; k < K; ++k)
    for (int m = 0; m < K - 1; ++m) T(k, m) = (m < k ? 1.0 : 0.0) - (m < mid ? 1.0 : 0.0);
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(K, K);
  Eigen::VectorXd h = Eigen::VectorXd::Zero(K);
  long data_rows = 0;
  struct Term {
    int k0;
    double f, w, lne;
  };
  std::vector<Term> terms;
  std::vector<std::pair<int, double>> row;
  for (const Track& tr : tracks) {
    // Interpolation of g at each code: (knot, weight) pairs; hat weights; a_j = w_j^2 / sum w^2.
    terms.clear();
    double wsum = 0;
    for (const auto& [z, e] : tr.obs) {
      const double pos = knot_position(z, max_code);
      const int k0 = std::min(int(pos), K - 2);
      terms.push_back({k0, pos - k0, hat(z, max_code), std::log(e)});
      wsum += terms.back().w * terms.back().w;
    }
    double mean_lne = 0;
    for (const Term& a : terms) mean_lne += a.w * a.w / wsum * a.lne;
    // Row j: w_j (phi_j - sum_k a_k phi_k) . g = w_j (ln e_j - sum_k a_k ln e_k).
    for (const Term& a : terms) {
      row.clear();
      row.push_back({a.k0, a.w * (1 - a.f)});
      row.push_back({a.k0 + 1, a.w * a.f});
      for (const Term& b : terms) {
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
  if (data_rows == 0) throw std::runtime_error("no usable samples in a channel");
  // Smoothness: lambda * (data rows per knot) * w(k)^2 (g_{k-1} - 2 g_k + g_{k+1})^2.
  add_smoothness(H, smoothness * double(data_rows) / K, max_code);
  Eigen::MatrixXd Q = T.transpose() * H * T;
  Q.diagonal().array() += 1e-12 * Q.diagonal().maxCoeff();
  const Eigen::VectorXd p = T.transpose() * h;
  const Eigen::VectorXd delta = nnls_gram(Q, p);
  const Eigen::VectorXd g = T * delta;
  std::vector<double> x(static_cast<std::size_t>(K));
  for (int k = 0; k < K; ++k) x[std::size_t(k)] = std::exp(g(k) - g(K - 1));
  return x;
}

// Knots -> the curve's contract: the channels tied at the middle code, flat from each channel's
// saturation code up, non-decreasing, the largest top knot 1.
ResponseCurve finish_curve(std::string model, nlohmann::json parameters, std::array<std::vector<double>, 3> knots,
                           const ResponseSamples& s) {
  ResponseCurve r;
  r.model = std::move(model);
  r.parameters = std::move(parameters);
  r.max_code = s.max_code;
  r.saturation = s.saturation;
  r.knots = std::move(knots);
  for (auto& k : r.knots)
    for (double& v : k)
      if (!std::isfinite(v) || v < 0) v = 0;
  // Flat above saturation: knots at or above the saturation code hold X(saturation code).
  for (int c = 0; c < 3; ++c) {
    auto& k = r.knots[std::size_t(c)];
    const double at = r.linear(c, s.saturation[std::size_t(c)]);
    for (std::size_t i = 0; i < k.size(); ++i)
      if (double(i) * s.max_code / double(k.size() - 1) >= s.saturation[std::size_t(c)]) k[i] = at;
    for (std::size_t i = 1; i < k.size(); ++i) k[i] = std::max(k[i], k[i - 1]);
  }
  try {
    tie_channels(r);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(e.what());
  }
  return r;
}

struct HeldOutStats {
  std::vector<double> sse;    // per held-out sample: squared code errors / max_code^2
  std::vector<int> n;         // per held-out sample: observations
  std::vector<bool> neutral;  // per held-out sample: rendered grey (see is_neutral)
  double mse() const {
    const double s = std::accumulate(sse.begin(), sse.end(), 0.0);
    const long c = std::accumulate(n.begin(), n.end(), 0L);
    return c > 0 ? s / double(c) : kInf;
  }
};

// A sample the camera rendered grey: in its best-exposed usable bracket (mean code nearest the
// middle) the three codes are within max(3, 8% of their mean) of each other.
bool is_neutral(const ResponseSamples& s, std::size_t i) {
  int best = -1;
  double best_d = kInf;
  for (int j = 0; j < s.saturated_from[i]; ++j) {
    const auto& z = s.codes[i][std::size_t(j)];
    const double d = std::abs((z[0] + z[1] + z[2]) / 3.0 - 0.5 * s.max_code);
    if (d < best_d) best_d = d, best = j;
  }
  if (best < 0) return false;
  const auto& z = s.codes[i][std::size_t(best)];
  const int hi = std::max({z[0], z[1], z[2]}), lo = std::min({z[0], z[1], z[2]});
  return hi - lo <= std::max(3.0 * s.max_code / 255.0, 0.08 * (z[0] + z[1] + z[2]) / 3.0);
}

// huber: observations with |error| above it (in units of max_code) count linearly (Huber's loss:
// d^2 below, 2 huber |d| - huber^2 above), so that a few heavy-tailed errors (JPEG blocks at an edge,
// a moving pixel) do not decide between models; 0: plain squares.
HeldOutStats held_out_stats(const ResponseCurve& curve, const ResponseSamples& s, double huber = 0) {
  // Predict codes: the radiance seen by a pixel's best-exposed usable bracket (code nearest the
  // middle), times e_j, through the inverse of the curve, against the codes observed in its other
  // usable brackets. Errors are in code units (noise there is roughly even across the range and
  // symmetric, so no curve can win by bending toward a noise bias as a log-space fit could).
  HeldOutStats st;
  for (std::size_t i = 0; i < s.codes.size(); ++i) {
    if (!s.held_out[i]) continue;
    const auto& e = s.exposures[std::size_t(s.view[i])];
    double sse = 0;
    int n = 0;
    for (int c = 0; c < 3; ++c) {
      std::vector<std::size_t> v;
      for (std::size_t j = 0; j < s.codes[i].size(); ++j)
        if (scored(s, i, j, c)) v.push_back(j);
      if (v.size() < 2) continue;
      std::size_t ref = v[0];
      for (std::size_t j : v)
        if (std::abs(s.codes[i][j][std::size_t(c)] - s.max_code / 2) <
            std::abs(s.codes[i][ref][std::size_t(c)] - s.max_code / 2))
          ref = j;
      const double L = curve.linear(c, s.codes[i][ref][std::size_t(c)]) / e[ref];
      for (std::size_t j : v) {
        if (j == ref) continue;
        const double d = (curve.code(c, L * e[j]) - s.codes[i][j][std::size_t(c)]) / s.max_code;
        sse += huber > 0 && std::abs(d) > huber ? 2 * huber * std::abs(d) - huber * huber : d * d;
        ++n;
      }
    }
    st.sse.push_back(sse);
    st.n.push_back(n);
    st.neutral.push_back(is_neutral(s, i));
  }
  return st;
}

// Observations a first curve cannot explain, removed before the models are compared:
//  - saturated signal below the saturation code (JPEG): from the longest usable bracket down,
//    while its code is within max_code / 8 of its channel's saturation code and more than 4 sigma
//    below what the shorter usable brackets predict (sigma: 1.4826 MAD of all prediction residuals
//    in the upper half of the codes), that bracket and the longer ones count as saturated;
//  - pixels whose residuals stay beyond 8 sigma after that (motion): dropped.
// Prediction: the inverse-variance-free mean of X(z_k) / e_k over the sample's other usable brackets
// k (shorter ones for the top test), through the inverse curve at e_j. Returns the observations removed.
struct Cleaning {
  long removed = 0;
  double sigma = 0;  // the residuals' robust standard deviation, codes
};
Cleaning clean_samples(ResponseSamples& s, const ResponseCurve& curve) {
  auto predict = [&](std::size_t i, int c, std::size_t j, bool shorter_only) {
    const auto& e = s.exposures[std::size_t(s.view[i])];
    double sum = 0;
    int n = 0;
    for (std::size_t k = 0; k < s.codes[i].size(); ++k) {
      if (k == j || (shorter_only && k > j) || !usable(s, i, k, c)) continue;
      sum += curve.linear(c, s.codes[i][k][std::size_t(c)]) / e[k];
      ++n;
    }
    return n > 0 ? curve.code(c, sum / n * e[j]) : -1.0;
  };
  std::vector<double> res;
  for (std::size_t i = 0; i < s.codes.size(); ++i)
    for (int c = 0; c < 3; ++c)
      for (std::size_t j = 0; j < s.codes[i].size(); ++j)
        if (usable(s, i, j, c) && s.codes[i][j][std::size_t(c)] >= s.max_code / 2) {
          const double p = predict(i, c, j, false);
          if (p >= 0) res.push_back(s.codes[i][j][std::size_t(c)] - p);
        }
  if (res.size() < 100) return {};
  std::vector<double> a = res;
  std::nth_element(a.begin(), a.begin() + long(a.size() / 2), a.end());
  const double med = a[a.size() / 2];
  for (double& v : a) v = std::abs(v - med);
  std::nth_element(a.begin(), a.begin() + long(a.size() / 2), a.end());
  const double sigma = std::max(0.5, 1.4826 * a[a.size() / 2]);
  long removed = 0;
  for (std::size_t i = 0; i < s.codes.size(); ++i) {
    for (int j = s.saturated_from[i] - 1; j > 0; --j) {
      bool leaked = false;
      for (int c = 0; c < 3 && !leaked; ++c) {
        const int z = s.codes[i][std::size_t(j)][std::size_t(c)];
        if (z < s.saturation[std::size_t(c)] - s.max_code / 8 || !usable(s, i, std::size_t(j), c)) continue;
        const double p = predict(i, c, std::size_t(j), true);
        leaked = p >= 0 && z - p < -4 * sigma;
      }
      if (!leaked) break;
      s.saturated_from[i] = j;
      ++removed;
    }
    bool gross = false;
    for (int c = 0; c < 3 && !gross; ++c)
      for (std::size_t j = 0; j < s.codes[i].size() && !gross; ++j)
        if (usable(s, i, j, c)) {
          const double p = predict(i, c, j, false);
          gross = p >= 0 && std::abs(s.codes[i][j][std::size_t(c)] - p) > 8 * sigma &&
                  s.codes[i][j][std::size_t(c)] >= s.max_code / 8;
        }
    if (gross) s.saturated_from[i] = 0, ++removed;
  }
  return {removed, sigma};
}

struct Entry {
  std::string fit_name, family;
  bool shared;
  int complexity;
  double smoothness = 1;  // debevec, robertson: multiplies RecoveryOptions::smoothness
};

// Every candidate in the order of the tie-break: identity, gamma, the smooth curves (smoother
// first), then the polynomials (more terms last): a smooth curve is the default shape, a polynomial
// replaces it only when it fits the held-out data clearly better. Robertson only when asked for
// (--model robertson): it is Debevec's family without an explicit smoothness prior, so in the
// automatic choice it would only add near ties.
std::vector<Entry> all_entries(bool with_robertson) {
  std::vector<Entry> e = {{"identity", "identity", true, 0}, {"gamma", "gamma", true, 1}, {"gamma", "gamma", false, 3}};
  for (bool shared : {true, false}) {
    const int k = shared ? kKnots : 3 * kKnots;
    for (double m : {10.0, 1.0}) e.push_back({"debevec", "debevec", shared, k, m});
    if (with_robertson) e.push_back({"robertson", "robertson", shared, k, 1.0});
  }
  for (bool shared : {true, false})
    for (int d = 2; d <= 5; ++d)
      e.push_back({"polynomial:" + std::to_string(d), "polynomial", shared, (shared ? 1 : 3) * (d - 1)});
  return e;
}

std::string label(const std::string& family, bool shared, const nlohmann::json& p) {
  std::string s = family;
  if (family == "polynomial" && p.contains("degree")) s += " " + std::to_string(p["degree"].get<int>());
  if ((family == "debevec" || family == "robertson") && p.contains("lambda")) {
    std::ostringstream l;
    l << " lambda " << p["lambda"].get<double>();
    s += l.str();
  }
  if (family != "identity") s += shared ? " (shared)" : " (per channel)";
  return s;
}

}  // namespace

ResponseSamples select_samples(const BracketStatistics& st, const std::array<int, 3>& saturation,
                               const RecoveryOptions& o) {
  if (st.views.empty())
    throw std::runtime_error("one bracket: a response cannot be recovered (give --response or --model identity)");
  ResponseSamples s;
  s.max_code = st.max_code;
  s.low_code = std::max(2, s.max_code / 128);
  s.saturation = saturation;
  struct Candidate {
    int view;
    std::size_t index;
    int sat_from;
    double proxy, roughness;
  };
  std::vector<Candidate> cand;
  for (std::size_t vi = 0; vi < st.views.size(); ++vi) {
    const ViewStatistics& v = st.views[vi];
    s.exposures.push_back(v.exposures);
    const int P = v.brackets;
    for (std::size_t i = 0; i < v.candidates(); ++i) {
      const std::uint16_t* z = v.sample(i);
      const int sat_from = saturated_from(z, P, saturation);
      // Codes must not decrease with exposure (else: motion); pick the best-exposed bracket.
      bool monotone = true;
      int best = -1, usable_brackets = 0;
      double best_d = kInf, best_mean = 0;
      for (int j = 0; j < sat_from; ++j) {
        bool any = false;
        double mean = 0;
        for (int ch = 0; ch < 3; ++ch) {
          const int zc = z[3 * j + ch];
          any = any || zc >= s.low_code;
          mean += zc / 3.0;
          if (j > 0 && zc + s.max_code / 50 < z[3 * (j - 1) + ch]) monotone = false;
        }
        if (!any) continue;
        ++usable_brackets;
        const double d = std::abs(mean - 0.5 * s.max_code);
        if (d < best_d) best_d = d, best = j, best_mean = mean;
      }
      if (!monotone || usable_brackets < 2) continue;
      cand.push_back({int(vi), i, sat_from,
                      std::log((best_mean + 1) / s.max_code) - std::log(v.exposures[std::size_t(best)]),
                      double(v.sample_roughness[i * std::size_t(P) + std::size_t(best)])});
    }
  }
  if (cand.size() < 20)
    throw std::runtime_error(
        "too few usable pixels for response recovery (every pixel saturated or black in every bracket?)");
  // Reject the roughest quarter, then stratify over 128 bins of the log-radiance proxy (code and
  // exposure together: a radiance level fixes the codes in every bracket), keeping the smoothest
  // pixels of each bin, taken from the views in turn (ties: raster order).
  std::vector<double> rough(cand.size());
  for (std::size_t i = 0; i < cand.size(); ++i) rough[i] = cand[i].roughness;
  std::nth_element(rough.begin(), rough.begin() + long(rough.size() * 3 / 4), rough.end());
  const double rough_limit = rough[rough.size() * 3 / 4];
  double lo = kInf, hi = -kInf;
  for (const auto& k : cand) lo = std::min(lo, k.proxy), hi = std::max(hi, k.proxy);
  const int bins = 128;
  const std::size_t nviews = st.views.size();
  std::vector<std::vector<std::vector<std::size_t>>> binned(bins, std::vector<std::vector<std::size_t>>(nviews));
  for (std::size_t i = 0; i < cand.size(); ++i) {
    if (cand[i].roughness > rough_limit) continue;
    const int k = hi > lo ? std::min(bins - 1, int((cand[i].proxy - lo) / (hi - lo) * bins)) : 0;
    binned[std::size_t(k)][std::size_t(cand[i].view)].push_back(i);
  }
  // The quota per bin: the largest q with sum_b min(size_b, q) <= samples (bins with fewer
  // candidates give all of theirs and leave their share to the others).
  std::vector<std::size_t> sizes;
  for (const auto& bin : binned) {
    std::size_t n = 0;
    for (const auto& per : bin) n += per.size();
    sizes.push_back(n);
  }
  std::size_t quota = std::size_t(std::max(2, o.samples / bins));
  for (std::size_t lo = quota, hi = std::size_t(o.samples) + 1; lo + 1 < hi;) {
    const std::size_t mid = (lo + hi) / 2;
    std::size_t total = 0;
    for (std::size_t n : sizes) total += std::min(n, mid);
    (total <= std::size_t(o.samples) ? lo : hi) = mid;
    quota = lo;
  }
  std::vector<std::size_t> chosen;
  for (auto& bin : binned) {
    for (auto& per : bin)
      std::stable_sort(per.begin(), per.end(),
                       [&](std::size_t a, std::size_t c) { return cand[a].roughness < cand[c].roughness; });
    std::size_t taken = 0;
    for (std::size_t round = 0; taken < quota; ++round) {
      bool any = false;
      for (auto& per : bin)
        if (round < per.size() && taken < quota) chosen.push_back(per[round]), ++taken, any = true;
      if (!any) break;
    }
  }
  std::stable_sort(chosen.begin(), chosen.end(),
                   [&](std::size_t a, std::size_t c) { return cand[a].proxy < cand[c].proxy; });
  for (std::size_t n = 0; n < chosen.size(); ++n) {
    const Candidate& k = cand[chosen[n]];
    const ViewStatistics& v = st.views[std::size_t(k.view)];
    const std::uint16_t* z = v.sample(k.index);
    std::vector<std::array<int, 3>> codes;
    for (int j = 0; j < v.brackets; ++j) codes.push_back({z[3 * j], z[3 * j + 1], z[3 * j + 2]});
    s.codes.push_back(codes);
    s.view.push_back(k.view);
    s.saturated_from.push_back(k.sat_from);
    s.held_out.push_back(n % 2 == 1);
  }
  if (s.codes.size() < 20) throw std::runtime_error("too few usable pixels for response recovery");
  return s;
}

ResponseCurve fit_response(const std::string& model, bool shared, const ResponseSamples& s, const RecoveryOptions& o) {
  if (model == "identity")
    return finish_curve("identity", nlohmann::json::object(),
                        {std::vector<double>{0, 1}, std::vector<double>{0, 1}, std::vector<double>{0, 1}}, s);
  // The parametric fits (unweighted in code) leave out the near-black codes, whose noise and
  // quantisation would dominate their log or ratio rows; the smooth curves weight them by the hat.
  const bool parametric = model == "gamma" || model.rfind("polynomial:", 0) == 0;
  const int min_code = parametric ? std::max(1, s.max_code / 20) : 0;
  std::array<std::vector<Track>, 3> per;
  if (shared) {
    per[0] = make_tracks(s, false, -1, min_code);
    if (per[0].empty()) throw std::runtime_error("no usable samples");
  } else {
    for (int c = 0; c < 3; ++c) {
      per[std::size_t(c)] = make_tracks(s, false, c, min_code);
      if (per[std::size_t(c)].empty()) throw std::runtime_error("no usable samples in channel " + std::to_string(c));
    }
  }
  const int channels = shared ? 1 : 3;
  std::array<std::vector<double>, 3> knots;
  nlohmann::json p = {{"shared", shared}};
  if (model == "gamma") {
    std::vector<double> g;
    for (int c = 0; c < channels; ++c) g.push_back(fit_gamma(per[std::size_t(c)], s.max_code));
    for (int c = 0; c < 3; ++c) {
      const double gc = g[std::size_t(shared ? 0 : c)];
      knots[std::size_t(c)] = sample_knots(parametric_knots(s.max_code), [&](double u) { return std::pow(u, gc); });
    }
    if (shared) g.assign(3, g[0]);
    p["gamma"] = g;
  } else if (model.rfind("polynomial:", 0) == 0) {
    const int degree = std::stoi(model.substr(11));
    if (degree < 2 || degree > 8) throw std::invalid_argument("polynomial degree must be 2..8");
    std::vector<std::vector<double>> cf;
    for (int c = 0; c < channels; ++c) cf.push_back(fit_polynomial(per[std::size_t(c)], s.max_code, degree));
    if (shared) cf.assign(3, cf[0]);
    bool monotone = true;
    for (int c = 0; c < 3; ++c) {
      auto& k = knots[std::size_t(c)];
      k = sample_knots(parametric_knots(s.max_code), [&](double u) { return polynomial_at(cf[std::size_t(c)], u); });
      // Non-decreasing below saturation (above it the curve is replaced by a flat top).
      for (std::size_t i = 1; i < k.size(); ++i)
        if (double(i) * s.max_code / double(k.size() - 1) <= s.saturation[std::size_t(c)] && k[i] < k[i - 1])
          monotone = false;
    }
    p["monotone"] = monotone;
    p["degree"] = degree;
    p["coefficients"] = cf;
  } else if (model == "robertson" || model == "debevec") {
    for (int c = 0; c < channels; ++c)
      knots[std::size_t(c)] = model == "robertson" ? fit_robertson(per[std::size_t(c)], s.max_code, o.smoothness)
                                                   : fit_debevec(per[std::size_t(c)], s.max_code, o.smoothness);
    if (shared) knots[1] = knots[2] = knots[0];
    p["lambda"] = o.smoothness;
    p["knots"] = kKnots;
  } else {
    throw std::invalid_argument("unknown response model '" + model +
                                "' (identity, gamma, polynomial, robertson, debevec)");
  }
  std::string family = model.substr(0, model.find(':'));
  return finish_curve(family, p, std::move(knots), s);
}

double held_out_error(const ResponseCurve& curve, const ResponseSamples& s) {
  return std::sqrt(held_out_stats(curve, s).mse());
}

ResponseRecovery recover_response(const std::vector<const BracketSet*>& views, const RecoveryOptions& o) {
  if (views.empty()) throw std::invalid_argument("recover_response: no views");
  BracketStatistics st(int(views.size()));
  for (const BracketSet* b : views) st.add(*b);
  return recover_response(st, o);
}

namespace {

// Paired comparison over the held-out samples: the mean squared error of a minus factor times b's,
// per observation, and its standard error (from the per-sample differences).
struct Comparison {
  double excess = 0, se = 0;
};
Comparison compare(const HeldOutStats& a, const HeldOutStats& b, double factor, bool neutral_only = false) {
  const std::size_t all = a.sse.size();
  long obs = 0;
  std::size_t M = 0;
  double total = 0;
  for (std::size_t i = 0; i < all; ++i)
    if (!neutral_only || a.neutral[i]) total += a.sse[i] - factor * b.sse[i], obs += b.n[i], ++M;
  double var = 0;
  for (std::size_t i = 0; i < all; ++i) {
    if (neutral_only && !a.neutral[i]) continue;
    const double d = a.sse[i] - factor * b.sse[i] - total / double(std::max<std::size_t>(1, M));
    var += d * d;
  }
  var *= double(M) / std::max<double>(1, double(M) - 1);
  return {total / double(std::max(1L, obs)), std::sqrt(var) / double(std::max(1L, obs))};
}

// The choice (see the header): first the channels, shared unless the best per-channel curve's mean
// squared error is below 1 / kChannelRatio of the best shared one's; then, among the candidates of
// that kind, the simplest within the held-out noise of the best.
constexpr double kChannelRatio = 1.5;

// Returns the chosen candidate's index.
std::size_t choose(ResponseRecovery& out, const std::vector<HeldOutStats>& stats, const RecoveryOptions& o) {
  auto& cand = out.candidates;
  const std::size_t N = cand.size();
  auto finite = [&](std::size_t k) { return std::isfinite(cand[k].held_out_error); };
  auto best_of = [&](auto&& in) {
    std::size_t b = N;
    for (std::size_t k = 0; k < N; ++k)
      if (finite(k) && in(k) && (b == N || cand[k].held_out_error < cand[b].held_out_error)) b = k;
    return b;
  };
  const std::size_t best_shared = best_of([&](std::size_t k) { return cand[k].shared; });
  const std::size_t best_separate = best_of([&](std::size_t k) { return !cand[k].shared; });
  if (best_shared == N && best_separate == N)
    throw std::runtime_error("no response model fits these brackets (is the exposure data right?)");
  bool shared = best_separate == N;
  double channel_margin = kInf;
  std::string channel_rival;
  if (best_shared != N && best_separate != N) {
    // Judged on the samples rendered grey when there are enough of them: there JPEG's chroma
    // subsampling and its decoder's clamping at the top code carry no colour error, which elsewhere
    // favours per-channel curves (by up to about 30% in mean squared error on JPEG shoots of a
    // shared-curve camera, measured) without bringing them closer to the camera's curve.
    const long neutral = std::count(stats[best_shared].neutral.begin(), stats[best_shared].neutral.end(), true);
    const Comparison c = compare(stats[best_shared], stats[best_separate], kChannelRatio, neutral >= 200);
    shared = c.excess <= 0;
    channel_margin = c.se > 0 ? std::abs(c.excess) / c.se : kInf;
    channel_rival = label(cand[shared ? best_separate : best_shared].model, !shared,
                          cand[shared ? best_separate : best_shared].parameters);
  }
  auto in_pool = [&](std::size_t k) { return cand[k].shared == shared || cand[k].model == "identity"; };
  const std::size_t best = best_of(in_pool);
  const double best_mse = stats[best].mse();
  std::vector<double> slack(N, -kInf);  // (threshold - excess) / se
  for (std::size_t k = 0; k < N; ++k) {
    if (!finite(k)) continue;
    const Comparison c = compare(stats[k], stats[best], 1.0);
    const double threshold = o.tie_sigmas * c.se + o.tie_relative * best_mse;
    cand[k].excess_sigmas = c.se > 0 ? c.excess / c.se : 0.0;
    cand[k].tied = in_pool(k) && c.excess <= threshold;
    slack[k] = c.se > 0 ? (threshold - c.excess) / c.se : (c.excess <= threshold ? kInf : -kInf);
  }
  std::size_t chosen = best;
  for (std::size_t k = 0; k < N; ++k)
    if (cand[k].tied) {
      chosen = k;
      break;
    }
  out.chosen = label(cand[chosen].model, cand[chosen].shared, cand[chosen].parameters);
  // Margin: the channel decision's, the chosen one's slack inside the tie, and how far each simpler
  // candidate of the pool is beyond it.
  out.margin_sigmas = channel_margin;
  std::string rival = channel_rival;
  if (chosen != best && slack[chosen] < out.margin_sigmas)
    out.margin_sigmas = slack[chosen], rival = label(cand[best].model, cand[best].shared, cand[best].parameters);
  for (std::size_t k = 0; k < chosen; ++k)
    if (finite(k) && in_pool(k) && -slack[k] < out.margin_sigmas)
      out.margin_sigmas = -slack[k], rival = label(cand[k].model, cand[k].shared, cand[k].parameters);
  out.near_tie = out.margin_sigmas < 1.0;
  if (out.near_tie) {
    std::ostringstream w;
    w.precision(2);
    w << "near tie: " << out.chosen << " chosen over " << rival << ", " << out.margin_sigmas
      << " standard errors of the held-out noise from the other choice; another shoot of this camera may choose differently";
    out.warning = w.str();
  }
  return chosen;
}

}  // namespace

ResponseRecovery recover_response(const BracketStatistics& st, const RecoveryOptions& o) {
  if (st.views.empty())
    throw std::runtime_error("one bracket: a response cannot be recovered (give --response or --model identity)");
  if (o.channels != "auto" && o.channels != "shared" && o.channels != "separate")
    throw std::invalid_argument("unknown channel mode '" + o.channels + "' (auto, shared, separate)");
  ResponseRecovery out;
  out.views = int(st.views.size());
  out.saturation = detect_saturation(st);
  for (int c = 0; c < 3; ++c)
    if (o.saturation_code[std::size_t(c)] > st.max_code)
      throw std::invalid_argument("saturation code " + std::to_string(o.saturation_code[std::size_t(c)]) +
                                  " is above the photos' top code " + std::to_string(st.max_code));
  for (int c = 0; c < 3; ++c)
    if (o.saturation_code[std::size_t(c)] > 0) {
      out.saturation.code[std::size_t(c)] = o.saturation_code[std::size_t(c)];
      out.saturation.source = "given";
    }
  ResponseSamples s = select_samples(st, out.saturation.code, o);
  const Cleaning cleaning = clean_samples(s, fit_response("debevec", true, s, o));
  out.removed_observations = cleaning.removed;
  const double huber = 3 * cleaning.sigma / s.max_code;
  ResponseSamples swapped = s;
  for (std::size_t i = 0; i < swapped.held_out.size(); ++i) swapped.held_out[i] = !s.held_out[i];
  for (bool h : s.held_out) (h ? out.held_out_samples : out.train_samples)++;
  std::vector<ResponseCurve> curves;
  std::vector<HeldOutStats> stats;
  bool known = o.model == "auto";
  for (const Entry& en : all_entries(o.model == "robertson")) {
    if (o.model != "auto" && o.model != en.family) continue;
    known = true;
    if (en.family != "identity" && o.channels != "auto" && en.shared != (o.channels == "shared")) continue;
    RecoveryOptions eo = o;
    eo.smoothness = o.smoothness * en.smoothness;
    // Two-fold: fitted on each half and scored on the other (each sample scored once, by a curve
    // that did not see it), which halves the noise of the comparison; the first half's fit is kept.
    ResponseCurve curve = fit_response(en.fit_name, en.shared, s, eo);
    ModelCandidate cand{en.family, en.shared, en.complexity, 0, 0, false, curve.parameters};
    HeldOutStats h = held_out_stats(curve, s, huber);
    {
      const ResponseCurve other = fit_response(en.fit_name, en.shared, swapped, eo);
      const HeldOutStats h2 = held_out_stats(other, swapped, huber);
      h.sse.insert(h.sse.end(), h2.sse.begin(), h2.sse.end());
      h.n.insert(h.n.end(), h2.n.begin(), h2.n.end());
      h.neutral.insert(h.neutral.end(), h2.neutral.begin(), h2.neutral.end());
      if (other.parameters.value("monotone", true) == false) cand.held_out_error = kInf;
    }
    if (std::isfinite(cand.held_out_error)) cand.held_out_error = std::sqrt(h.mse());
    try {
      curve.validate();
    } catch (const std::invalid_argument&) {
      cand.held_out_error = kInf;
    }
    if (curve.parameters.value("monotone", true) == false) cand.held_out_error = kInf;  // a decreasing polynomial
    out.candidates.push_back(cand);
    curves.push_back(std::move(curve));
    stats.push_back(std::move(h));
  }
  if (!known || out.candidates.empty())
    throw std::invalid_argument("unknown response model '" + o.model +
                                "' (auto, identity, gamma, polynomial, robertson, debevec)");
  out.curve = curves[choose(out, stats, o)];
  return out;
}

ResponseRecovery recover_response(const BracketSet& b, const RecoveryOptions& o) {
  return recover_response(std::vector<const BracketSet*>{&b}, o);
}

nlohmann::json recovery_json(const ResponseRecovery& r) {
  nlohmann::json cands = nlohmann::json::array();
  for (const auto& c : r.candidates)
    cands.push_back(
        {{"model", c.model},
         {"shared", c.shared},
         {"complexity", c.complexity},
         {"held_out_error",
          std::isfinite(c.held_out_error) ? nlohmann::json(c.held_out_error) : nlohmann::json("rejected")},
         {"excess_sigmas", std::isfinite(c.held_out_error) ? nlohmann::json(c.excess_sigmas) : nlohmann::json()},
         {"tied", c.tied},
         {"parameters", c.parameters}});
  return {{"chosen", r.chosen},
          {"margin_sigmas", std::isfinite(r.margin_sigmas) ? nlohmann::json(r.margin_sigmas) : nlohmann::json()},
          {"near_tie", r.near_tie},
          {"warning", r.warning},
          {"saturation_code", r.saturation.code},
          {"saturation_source", r.saturation.source},
          {"views", r.views},
          {"train_samples", r.train_samples},
          {"held_out_samples", r.held_out_samples},
          {"candidates", cands}};
}

}  // namespace rsibr
