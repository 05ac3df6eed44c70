// A camera's inverse response: code z -> linear signal X, per channel, normalised so that the
// largest top knot over the channels is X = 1 (X is the recorded signal L * e * k divided by the
// signal that saturates; the channels share that unit, so their ratios are the camera's colour).
// Stored as knots uniformly spaced in code over [0, max_code] with linear interpolation between
// them (for 8-bit input one knot per code), with the code at which each channel saturates. Saved as
// a small JSON file per camera and reused.
#pragma once

#include <nlohmann/json.hpp>

#include <array>
#include <filesystem>
#include <string>
#include <vector>

namespace rsibr {

struct ResponseCurve {
  std::string model = "identity";                        // identity, gamma, polynomial, robertson, debevec
  nlohmann::json parameters = nlohmann::json::object();  // model parameters (gamma, coefficients, ...)
  int max_code = 255;
  std::array<std::vector<double>, 3> knots;   // X at codes k * max_code / (K-1), K >= 2, non-decreasing
  std::array<int, 3> saturation{-1, -1, -1};  // per channel: codes at or above are saturated; -1: the default

  // The channel's saturation code (default_saturation_code(max_code) when not set).
  int saturation_code(int channel) const;

  // X for code z (clamped to [0, max_code]) in channel c.
  double linear(int channel, double z) const;
  // The inverse: the (fractional) code whose X is x, clamped to [0, max_code]; on a flat stretch
  // the lowest such code.
  double code(int channel, double x) const;
  // Per-code tables for the merge: X(z) and the quantisation variance of X,
  // ((X(z+1/2) - X(z-1/2))^2 / 12), each max_code+1 floats per channel.
  void tables(std::array<std::vector<float>, 3>& x, std::array<std::vector<float>, 3>& quantisation_var) const;

  // Throws std::invalid_argument naming what is wrong (sizes, non-finite, decreasing, a top knot
  // above 1 or none at 1, a saturation code outside (0, max_code]).
  void validate() const;

  static ResponseCurve identity(int max_code);
  // A curve from X = f_c(u), u = z / max_code in [0,1], sampled at `knots` knots and normalised.
  template <class F>
  static ResponseCurve sampled(std::string model, int max_code, int knot_count, F&& f);
};

// The channels' common unit, the convention every recovered curve follows (a camera's own white
// balance): each channel scaled so that X_c(max_code / 2) is the same for all three (equal middle
// codes are grey), then all together so that the largest top knot is 1. Throws
// std::invalid_argument when a channel is 0 at the middle code.
void tie_channels(ResponseCurve& curve);

// JSON: {"rsibr_response": 1, "model", "parameters", "max_code", "saturation_code": [R, G, B],
// "knots": [[R...],[G...],[B...]]} plus any extra keys given (camera name, held-out errors). Written
// atomically. Files without saturation_code (older ones) load with the default.
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
