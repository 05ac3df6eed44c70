#include "capture/camera_response.h"

#include "core/srgb_curve.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace rsibr {
namespace {

struct NakaRushton {
  double g, a;
};
constexpr NakaRushton kMeasured[3] = {{0.62, 0.35}, {0.58, 0.30}, {0.66, 0.42}};

// The filmic contrast curve on the encoded value u in [0,1] (see the header).
constexpr double kFilmicW = 0.5, kFilmicA = 1.6;
double filmic_contrast(double u) {
  const double p = std::pow(u, kFilmicA), q = std::pow(1 - u, kFilmicA);
  return (1 - kFilmicW) * u + kFilmicW * p / (p + q);
}

}  // namespace

const std::vector<std::string>& CameraResponse::kinds() {
  static const std::vector<std::string> k = {"linear", "srgb", "measured", "filmic"};
  return k;
}

CameraResponse::CameraResponse(const std::string& kind) : kind_(kind) {
  if (std::find(kinds().begin(), kinds().end(), kind) == kinds().end())
    throw std::invalid_argument("unknown camera response '" + kind + "' (linear, srgb, measured, filmic)");
}

double CameraResponse::code(double x, int c) const {
  x = std::clamp(x, 0.0, 1.0);
  if (kind_ == "linear") return x;
  if (kind_ == "srgb") return srgb_encode(x);
  if (kind_ == "filmic") return filmic_contrast(srgb_encode(x));
  const NakaRushton& p = kMeasured[c];
  const double xg = std::pow(x, p.g);
  return (1 + p.a) * xg / (xg + p.a);
}

double CameraResponse::relative(double f, int c) const {
  f = std::clamp(f, 0.0, 1.0);
  if (kind_ == "linear") return f;
  if (kind_ == "srgb") return srgb_decode(f);
  if (kind_ == "filmic") {
    // Bisection on the increasing contrast curve: 64 halvings reach the double's resolution.
    double lo = 0, hi = 1;
    for (int i = 0; i < 64 && hi - lo > 0; ++i) {
      const double mid = 0.5 * (lo + hi);
      (filmic_contrast(mid) < f ? lo : hi) = mid;
    }
    return srgb_decode(0.5 * (lo + hi));
  }
  const NakaRushton& p = kMeasured[c];
  return std::pow(p.a * f / (1 + p.a - f), 1.0 / p.g);
}

std::vector<std::vector<double>> CameraResponse::table(int max_code) const {
  std::vector<std::vector<double>> out;
  for (int i = 0; i <= max_code; ++i) {
    const double f = double(i) / max_code;
    out.push_back({double(i), relative(f, 0), relative(f, 1), relative(f, 2)});
  }
  return out;
}

}  // namespace rsibr
