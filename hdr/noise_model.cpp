#include "hdr/noise_model.h"

#include "hdr/nnls.h"
#include "hdr/saturation_level.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace rsibr {
namespace {

struct Row {
  double f_shot, f_read, f_code, f_texture, target, expected_short;
};

}  // namespace

NoiseModel estimate_noise(const std::vector<const BracketSet*>& views, const ResponseCurve& curve) {
  BracketStatistics st(int(views.size()));
  for (const BracketSet* b : views) {
    if (curve.max_code != b->max_code)
      throw std::invalid_argument("estimate_noise: the response curve's code range differs from the brackets'");
    st.add(*b);
  }
  return estimate_noise(st, curve);
}

NoiseModel estimate_noise(const BracketStatistics& st, const ResponseCurve& curve) {
  NoiseModel out;
  if (st.views.empty()) return out;
  if (curve.max_code != st.max_code)
    throw std::invalid_argument("estimate_noise: the response curve's code range differs from the brackets'");
  std::array<std::vector<float>, 3> tx, tq;
  curve.tables(tx, tq);
  const std::array<int, 3> sat{curve.saturation_code(0), curve.saturation_code(1), curve.saturation_code(2)};
  std::array<std::vector<Row>, 3> rows;
  // Pixels are chosen by the longer (less noisy) bracket of each pair: selecting on the noisy
  // shorter one would truncate its noise at the dark end and hide the read noise. The shorter one
  // must stay clear of the black clip: rows whose expected shorter-bracket signal is below four
  // read-noise sigmas (of the current estimate) are left out.
  const int low = std::max(2, st.max_code / 1000);
  for (const ViewStatistics& v : st.views) {
    for (std::size_t i = 0; i < v.noise_pixels(); ++i) {
      const std::uint16_t* z = v.noise_pixel(i);
      const float* act = v.noise_pixel_activity(i);
      const int from = saturated_from(z, v.brackets, sat);
      for (int j = 0; j + 1 < from; ++j) {
        const std::uint16_t* zj = z + 3 * j;
        const std::uint16_t* zk = z + 3 * (j + 1);
        if (zk[0] < low || zk[1] < low || zk[2] < low) continue;
        const double ej = v.exposures[std::size_t(j)], ek = v.exposures[std::size_t(j + 1)];
        for (int ch = 0; ch < 3; ++ch) {
          const auto& x = tx[std::size_t(ch)];
          const auto& q = tq[std::size_t(ch)];
          const double Lj = x[zj[ch]] / ej, Lk = x[zk[ch]] / ek;
          const double d = Lj - Lk;
          const double qj = q[zj[ch]] / (ej * ej), qk = q[zk[ch]] / (ek * ek);  // step^2 / 12 / e^2
          const double aj = act[3 * j + ch], ak = act[3 * (j + 1) + ch];
          rows[std::size_t(ch)].push_back({Lk * (1 / ej + 1 / ek), 1 / (ej * ej) + 1 / (ek * ek), 12 * (qj + qk),
                                           12 * (qj * aj * aj + qk * ak * ak), d * d - qj - qk, Lk * ej});
        }
      }
    }
  }
  if (rows[0].size() < 100) return out;
  for (int ch = 0; ch < 3; ++ch) {
    const auto& rs = rows[std::size_t(ch)];
    // Unknowns: shot, read, code, texture. A constant code step (a linear curve) makes the code
    // term a multiple of the read term: the two cannot be told apart, so code stays 0 then.
    double sr = 0, sc = 0, srr = 0, scc = 0, src = 0;
    for (const auto& row : rs)
      sr += row.f_read, sc += row.f_code, srr += row.f_read * row.f_read, scc += row.f_code * row.f_code,
          src += row.f_read * row.f_code;
    const double nrow = double(rs.size());
    const double cov = src / nrow - sr * sc / (nrow * nrow), vr = srr / nrow - sr * sr / (nrow * nrow),
                 vc = scc / nrow - sc * sc / (nrow * nrow);
    const bool fit_code = st.lossy && vr > 0 && vc > 0 && std::abs(cov) / std::sqrt(vr * vc) < 0.98;
    const bool fit_texture = st.lossy;
    Eigen::Vector4d x(1e-4, 1e-8, 0, 0);
    for (int it = 0; it < 8; ++it) {
      Eigen::Matrix4d A = Eigen::Matrix4d::Zero();
      Eigen::Vector4d y = Eigen::Vector4d::Zero();
      long used = 0;
      const double floor = 4 * std::sqrt(x(1));
      for (const auto& row : rs) {
        if (row.expected_short < floor) continue;
        const Eigen::Vector4d f(row.f_shot, row.f_read, fit_code ? row.f_code : 0.0, fit_texture ? row.f_texture : 0.0);
        const double pred = std::max(1e-300, x.dot(f));
        if (it > 0 && row.target > 100 * pred) continue;  // beyond 10 sigma: motion or a curve error, not noise
        const double w = 1.0 / (pred * pred);
        A += w * f * f.transpose();
        y += w * f * row.target;
        ++used;
      }
      if (used < 100) break;
      // Non-negative solve on unknowns scaled to comparable sizes (an empty column stays 0).
      Eigen::Vector4d d;
      for (int k = 0; k < 4; ++k) d(k) = A(k, k) > 0 ? 1 / std::sqrt(A(k, k)) : 0.0;
      Eigen::MatrixXd Q = d.asDiagonal() * A * d.asDiagonal();
      for (int k = 0; k < 4; ++k) Q(k, k) = A(k, k) > 0 ? Q(k, k) + 1e-12 : 1.0;
      const Eigen::VectorXd sol = nnls_gram(Q, Eigen::VectorXd(d.cwiseProduct(y)));
      const Eigen::Vector4d next = d.cwiseProduct(Eigen::Vector4d(sol));
      if (!next.allFinite()) break;
      x = next;
      x(0) = std::max(x(0), 1e-12);
      x(1) = std::max(x(1), 1e-14);
    }
    out.shot[std::size_t(ch)] = x(0);
    out.read[std::size_t(ch)] = x(1);
    out.code[std::size_t(ch)] = x(2);
    out.texture[std::size_t(ch)] = x(3);
  }
  out.source = "estimated";
  out.views = int(st.views.size());
  return out;
}

NoiseModel estimate_noise(const BracketSet& b, const ResponseCurve& curve, int saturation_code) {
  ResponseCurve c = curve;
  c.saturation = {saturation_code, saturation_code, saturation_code};
  return estimate_noise(std::vector<const BracketSet*>{&b}, c);
}

}  // namespace rsibr
