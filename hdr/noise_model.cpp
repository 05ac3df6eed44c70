#include "hdr/noise_model.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace rsibr {

NoiseModel estimate_noise(const BracketSet& b, const ResponseCurve& curve, int saturation_code) {
  NoiseModel out;
  if (curve.max_code != b.max_code)
    throw std::invalid_argument("estimate_noise: the response curve's code range differs from the brackets'");
  if (b.size() < 2) return out;
  std::array<std::vector<float>, 3> tx, tq;
  curve.tables(tx, tq);
  // Pixels are chosen by the longer (less noisy) bracket of each pair: selecting on the noisy
  // shorter one would truncate its noise at the dark end and hide the read noise. The shorter one
  // must stay clear of the black clip: rows whose expected shorter-bracket signal is below four
  // read-noise sigmas (of the current estimate) are left out.
  const int low = std::max(2, b.max_code / 1000);
  const int H = b.rows(), W = b.cols();
  const int stride = std::max(1, int(std::sqrt(double(H) * W / 200000.0)));
  struct Row { double f_shot, f_read, target, expected_short; };
  std::array<std::vector<Row>, 3> rows;
  for (int r = 0; r < H; r += stride)
    for (int c = 0; c < W; c += stride)
      for (std::size_t j = 0; j + 1 < b.size(); ++j) {
        const auto zj = b.codes[j].at<cv::Vec3w>(r, c), zk = b.codes[j + 1].at<cv::Vec3w>(r, c);
        bool ok = true;
        for (int ch = 0; ch < 3; ++ch) ok = ok && zk[ch] >= low && zk[ch] < saturation_code && zj[ch] < saturation_code;
        if (!ok) continue;
        const double ej = b.exposures[j], ek = b.exposures[j + 1];
        for (int ch = 0; ch < 3; ++ch) {
          const auto& x = tx[std::size_t(ch)];
          const auto& q = tq[std::size_t(ch)];
          const double Lj = x[zj[ch]] / ej, Lk = x[zk[ch]] / ek;
          const double d = Lj - Lk;
          const double quant = q[zj[ch]] / (ej * ej) + q[zk[ch]] / (ek * ek);
          rows[std::size_t(ch)].push_back({Lk * (1 / ej + 1 / ek), 1 / (ej * ej) + 1 / (ek * ek), d * d - quant, Lk * ej});
        }
      }
  if (rows[0].size() < 100) return out;
  for (int ch = 0; ch < 3; ++ch) {
    double shot = 1e-4, read = 1e-8;
    const auto& rs = rows[std::size_t(ch)];
    for (int it = 0; it < 8; ++it) {
      Eigen::Matrix2d A = Eigen::Matrix2d::Zero();
      Eigen::Vector2d y = Eigen::Vector2d::Zero();
      long used = 0;
      const double floor = 4 * std::sqrt(read);
      for (const auto& row : rs) {
        if (row.expected_short < floor) continue;
        const double pred = std::max(1e-300, shot * row.f_shot + read * row.f_read);
        if (it > 0 && row.target > 25 * pred) continue;  // motion or a curve error, not noise
        const double w = 1.0 / (pred * pred);
        const Eigen::Vector2d f(row.f_shot, row.f_read);
        A += w * f * f.transpose();
        y += w * f * row.target;
        ++used;
      }
      if (used < 100) break;
      const Eigen::Vector2d s = A.ldlt().solve(y);
      if (!s.allFinite()) break;
      shot = std::max(s(0), 1e-12);
      read = std::max(s(1), 1e-14);
    }
    out.shot[std::size_t(ch)] = shot;
    out.read[std::size_t(ch)] = read;
  }
  out.source = "estimated";
  return out;
}

}  // namespace rsibr
