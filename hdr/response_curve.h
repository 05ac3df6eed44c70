// A camera's inverse response: code z -> linear signal X, per channel, normalised so that the top
// code maps to X = 1 (X is the recorded signal L * e * k divided by the signal that saturates).
// Stored as knots uniformly spaced in code over [0, max_code] with linear interpolation between
// them (for 8-bit input one knot per code). Saved as a small JSON file per camera and reused.
#pragma once

#include <nlohmann/json.hpp>

#include <array>
#include <filesystem>
#include <string>
#include <vector>

namespace rsibr {

struct ResponseCurve {
  std::string model = "identity";  // identity, gamma, polynomial, robertson, debevec
  nlohmann::json parameters = nlohmann::json::object();  // model parameters (gamma, coefficients, ...)
  int max_code = 255;
  std::array<std::vector<double>, 3> knots;  // X at codes k * max_code / (K-1), K >= 2, non-decreasing

  // X for code z (clamped to [0, max_code]) in channel c.
  double linear(int channel, double z) const;
  // The inverse: the (fractional) code whose X is x, clamped to [0, max_code]; on a flat stretch
  // the lowest such code.
  double code(int channel, double x) const;
  // Per-code tables for the merge: X(z) and the quantisation variance of X,
  // ((X(z+1/2) - X(z-1/2))^2 / 12), each max_code+1 floats per channel.
  void tables(std::array<std::vector<float>, 3>& x, std::array<std::vector<float>, 3>& quantisation_var) const;

  // Throws std::invalid_argument naming what is wrong (sizes, non-finite, decreasing, top != 1).
  void validate() const;

  static ResponseCurve identity(int max_code);
  // A curve from X = f_c(u), u = z / max_code in [0,1], sampled at `knots` knots and normalised.
  template <class F>
  static ResponseCurve sampled(std::string model, int max_code, int knot_count, F&& f);
};

// JSON: {"rsibr_response": 1, "model", "parameters", "max_code", "knots": [[R...],[G...],[B...]]}
// plus any extra keys given (camera name, held-out errors). Written atomically.
void save_response(const std::filesystem::path& path, const ResponseCurve& curve,
                   const nlohmann::json& extra = nlohmann::json::object());
// Throws std::runtime_error("<path>: <problem>").
ResponseCurve load_response(const std::filesystem::path& path);

template <class F>
ResponseCurve ResponseCurve::sampled(std::string model, int max_code, int knot_count, F&& f) {
  ResponseCurve r;
  r.model = std::move(model);
  r.max_code = max_code;
  for (int c = 0; c < 3; ++c) {
    r.knots[std::size_t(c)].resize(std::size_t(knot_count));
    const double top = f(c, 1.0);
    for (int k = 0; k < knot_count; ++k)
      r.knots[std::size_t(c)][std::size_t(k)] = f(c, double(k) / (knot_count - 1)) / top;
  }
  return r;
}

}  // namespace rsibr
