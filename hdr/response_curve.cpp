#include "hdr/response_curve.h"

#include "formats/atomic_file.h"
#include "formats/input_file.h"
#include "hdr/saturation_level.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <stdexcept>

namespace rsibr {

double ResponseCurve::linear(int channel, double z) const {
  const auto& k = knots[std::size_t(channel)];
  const double pos = std::clamp(z, 0.0, double(max_code)) * double(k.size() - 1) / max_code;
  const std::size_t i = std::min(std::size_t(pos), k.size() - 2);
  const double f = pos - double(i);
  return k[i] * (1 - f) + k[i + 1] * f;
}

double ResponseCurve::code(int channel, double x) const {
  const auto& k = knots[std::size_t(channel)];
  if (x <= k.front()) return 0.0;
  if (x >= k.back()) return double(max_code);
  const std::size_t i = std::size_t(std::upper_bound(k.begin(), k.end(), x) - k.begin()) - 1;  // k[i] <= x < k[i+1]
  const double f = (x - k[i]) / (k[i + 1] - k[i]);
  return (double(i) + f) * max_code / double(k.size() - 1);
}

void ResponseCurve::tables(std::array<std::vector<float>, 3>& x, std::array<std::vector<float>, 3>& qv) const {
  for (int c = 0; c < 3; ++c) {
    auto& xs = x[std::size_t(c)];
    auto& qs = qv[std::size_t(c)];
    xs.resize(std::size_t(max_code) + 1);
    qs.resize(std::size_t(max_code) + 1);
    for (int z = 0; z <= max_code; ++z) {
      xs[std::size_t(z)] = float(linear(c, z));
      const double step = linear(c, z + 0.5) - linear(c, z - 0.5);
      qs[std::size_t(z)] = float(step * step / 12.0);
    }
  }
}

int ResponseCurve::saturation_code(int channel) const {
  const int s = saturation[std::size_t(channel)];
  return s > 0 ? s : default_saturation_code(max_code);
}

void ResponseCurve::validate() const {
  if (max_code != 255 && max_code != 65535) throw std::invalid_argument("max_code must be 255 or 65535");
  double top = 0;
  for (int c = 0; c < 3; ++c) {
    if (saturation[std::size_t(c)] == 0 || saturation[std::size_t(c)] > max_code || saturation[std::size_t(c)] < -1)
      throw std::invalid_argument("channel " + std::to_string(c) + ": saturation code must be in (0, max_code]");
    const auto& k = knots[std::size_t(c)];
    const std::string ch = "channel " + std::to_string(c);
    if (k.size() < 2) throw std::invalid_argument(ch + ": fewer than 2 knots");
    for (std::size_t i = 0; i < k.size(); ++i) {
      if (!std::isfinite(k[i]) || k[i] < 0)
        throw std::invalid_argument(ch + ": knot " + std::to_string(i) + " is negative or not finite");
      if (i > 0 && k[i] < k[i - 1]) throw std::invalid_argument(ch + ": decreasing at knot " + std::to_string(i));
    }
    if (k.back() > 1.0 + 1e-6) throw std::invalid_argument(ch + ": the top knot must be at most 1");
    top = std::max(top, k.back());
  }
  if (std::abs(top - 1.0) > 1e-6) throw std::invalid_argument("the largest top knot must be 1");
}

ResponseCurve ResponseCurve::identity(int max_code) {
  return sampled("identity", max_code, 2, [](int, double u) { return u; });
}

void tie_channels(ResponseCurve& r) {
  const double mid = 0.5 * r.max_code;
  const double ref = r.linear(1, mid);
  for (int c = 0; c < 3; ++c) {
    const double here = r.linear(c, mid);
    if (!(here > 0) || !(ref > 0)) throw std::invalid_argument("degenerate response (0 at the middle code)");
    for (double& v : r.knots[std::size_t(c)]) v *= ref / here;
  }
  double top = 0;
  for (const auto& k : r.knots) top = std::max(top, k.back());
  for (auto& k : r.knots)
    for (double& v : k) v = std::min(1.0, v / top);
}

void save_response(const std::filesystem::path& path, const ResponseCurve& curve, const nlohmann::json& extra) {
  nlohmann::json j = extra;
  j["rsibr_response"] = 1;
  j["model"] = curve.model;
  j["parameters"] = curve.parameters;
  j["max_code"] = curve.max_code;
  j["saturation_code"] = {curve.saturation_code(0), curve.saturation_code(1), curve.saturation_code(2)};
  j["knots"] = {curve.knots[0], curve.knots[1], curve.knots[2]};
  // The camera name is not always UTF-8: bad bytes are replaced.
  write_text_atomically(path, j.dump(1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n");
}

ResponseCurve load_response(const std::filesystem::path& path) {
  require_regular_file(path);
  std::ifstream f(path);
  if (!f) throw std::runtime_error(path.string() + ": cannot open the response curve");
  try {
    const nlohmann::json j = nlohmann::json::parse(f);
    if (j.value("rsibr_response", 0) != 1)
      throw std::invalid_argument("not an rsibr response file (rsibr_response: 1 missing)");
    ResponseCurve r;
    r.model = j.at("model").get<std::string>();
    r.parameters = j.value("parameters", nlohmann::json::object());
    r.max_code = j.at("max_code").get<int>();
    const auto& k = j.at("knots");
    if (!k.is_array() || k.size() != 3) throw std::invalid_argument("knots must be three lists");
    for (int c = 0; c < 3; ++c) r.knots[std::size_t(c)] = k[std::size_t(c)].get<std::vector<double>>();
    if (j.contains("saturation_code")) {
      const auto& s = j.at("saturation_code");
      if (!s.is_array() || s.size() != 3) throw std::invalid_argument("saturation_code must be three codes");
      for (int c = 0; c < 3; ++c) r.saturation[std::size_t(c)] = s[std::size_t(c)].get<int>();
    }
    r.validate();
    return r;
  } catch (const std::exception& e) {
    throw std::runtime_error(path.string() + ": " + e.what());
  }
}

}  // namespace rsibr
