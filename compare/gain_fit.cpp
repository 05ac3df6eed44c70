#include "compare/gain_fit.h"
#include "core/luminance.h"

#include <ceres/ceres.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <utility>

namespace rsibr {
namespace {

struct Texel {
  std::array<double, 3> a, b;
  double weight;
};

// residual_c = ln(exp(theta_c) a_c + eps) - ln(b_c + eps); d residual_c / d theta_c = g a / (g a + eps)
// (the Jacobian is diagonal: channels couple only through the loss).
class LogGainCost final : public ceres::SizedCostFunction<3, 3> {
 public:
  LogGainCost(const Texel& t, double eps) : t_(t), eps_(eps) {}
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    log_gain_residuals(parameters[0], t_.a.data(), t_.b.data(), eps_, residuals, jacobians ? jacobians[0] : nullptr);
    // A step that overflows is refused (Ceres then shortens it), never propagated.
    return std::isfinite(residuals[0]) && std::isfinite(residuals[1]) && std::isfinite(residuals[2]);
  }

 private:
  Texel t_;
  double eps_;
};

double weighted_median(std::vector<std::pair<double, double>> values) {  // (value, weight)
  std::sort(values.begin(), values.end());
  double total = 0;
  for (const auto& v : values) total += v.second;
  double run = 0;
  for (const auto& v : values) {
    run += v.second;
    if (run >= 0.5 * total) return v.first;
  }
  return values.empty() ? 0.0 : values.back().first;
}

}  // namespace

void log_gain_residuals(const double theta[3], const double a[3], const double b[3], double eps, double residuals[3],
                        double* jacobian) {
  for (int c = 0; c < 3; ++c) {
    const double ga = std::exp(theta[c]) * std::max(0.0, a[c]);
    residuals[c] = std::log(ga + eps) - std::log(std::max(0.0, b[c]) + eps);
    if (jacobian)
      for (int k = 0; k < 3; ++k) jacobian[3 * c + k] = k == c ? ga / (ga + eps) : 0.0;
  }
}

GainFit fit_gains(const std::vector<WeightedImages>& images, const GainFitOptions& options) {
  if (!(options.log_epsilon > 0) || !(options.loss_scale > 0))
    throw std::invalid_argument("gain fit: the log epsilon and the loss scale must be positive");
  long weighted = 0;
  for (const WeightedImages& im : images) weighted += cv::countNonZero(im.weight > 0);
  if (weighted == 0) throw std::invalid_argument("gain fit: no texel has a non-zero weight");
  const long stride = options.max_texels > 0 ? (weighted + options.max_texels - 1) / options.max_texels : 1;

  std::vector<Texel> texels;
  texels.reserve(std::size_t(weighted / stride + 1));
  long index = 0;
  double weight_sum = 0;
  for (const WeightedImages& im : images)
    for (int r = 0; r < im.a.rows; ++r) {
      const float* pa = im.a.ptr<float>(r);
      const float* pb = im.b.ptr<float>(r);
      const float* pw = im.weight.ptr<float>(r);
      for (int x = 0; x < im.a.cols; ++x) {
        if (!(pw[x] > 0)) continue;
        if (index++ % stride != 0) continue;
        Texel t;
        for (int c = 0; c < 3; ++c) {
          t.a[std::size_t(c)] = std::max(0.0, double(pa[3 * x + c]));
          t.b[std::size_t(c)] = std::max(0.0, double(pb[3 * x + c]));
        }
        t.weight = pw[x];
        weight_sum += t.weight;
        texels.push_back(t);
      }
    }
  const double mean_weight = weight_sum / double(texels.size());
  const double eps = options.log_epsilon;

  std::array<double, 3> theta{}, start{};
  for (int c = 0; c < 3; ++c) {
    // Texels where both are positive give the ratio without eps, which matters when A is many
    // stops off B (eps, from B's level, would swamp A); otherwise the eps form.
    std::vector<std::pair<double, double>> ratios;
    ratios.reserve(texels.size());
    for (const Texel& t : texels)
      if (t.a[std::size_t(c)] > 0 && t.b[std::size_t(c)] > 0)
        ratios.emplace_back(std::log(t.b[std::size_t(c)] / t.a[std::size_t(c)]), t.weight);
    if (ratios.empty())
      for (const Texel& t : texels)
        ratios.emplace_back(std::log((t.b[std::size_t(c)] + eps) / (t.a[std::size_t(c)] + eps)), t.weight);
    theta[std::size_t(c)] = weighted_median(std::move(ratios));
  }
  start = theta;

  ceres::CauchyLoss cauchy(options.loss_scale);
  ceres::Problem problem;
  for (const Texel& t : texels)
    problem.AddResidualBlock(new LogGainCost(t, eps),
                             new ceres::ScaledLoss(&cauchy, t.weight / mean_weight, ceres::DO_NOT_TAKE_OWNERSHIP),
                             theta.data());
  ceres::Solver::Options so;
  so.linear_solver_type = ceres::DENSE_QR;
  so.num_threads = 1;
  so.max_num_iterations = options.max_iterations;
  so.function_tolerance = 1e-15;
  so.gradient_tolerance = 1e-15;
  so.parameter_tolerance = 1e-14;
  so.logging_type = ceres::SILENT;
  so.minimizer_progress_to_stdout = false;
  ceres::Solver::Summary summary;
  ceres::Solve(so, &problem, &summary);

  GainFit fit;
  bool finite = true;
  for (double t : theta) finite = finite && std::isfinite(t) && std::isfinite(std::exp(t)) && std::exp(t) > 0;
  if (!finite) theta = start;  // the robust start is always finite
  for (int c = 0; c < 3; ++c) fit.gains[std::size_t(c)] = std::exp(theta[std::size_t(c)]);
  const double y = luminance(fit.gains);
  fit.exposure_stops = std::log2(y);
  for (int c = 0; c < 3; ++c) fit.chroma[std::size_t(c)] = fit.gains[std::size_t(c)] / y;
  fit.texels_used = long(texels.size());
  fit.iterations = int(summary.iterations.size());
  fit.converged = finite && summary.termination_type == ceres::CONVERGENCE;
  fit.initial_cost = summary.initial_cost;
  fit.final_cost = summary.final_cost;
  return fit;
}

cv::Mat apply_gains(const cv::Mat& rgb, const std::array<double, 3>& gains) {
  cv::Mat out;
  cv::multiply(rgb, cv::Scalar(gains[0], gains[1], gains[2]), out);
  return out;
}

}  // namespace rsibr
