#include "lights/recovered_probe.h"

#include "bake/brdf_spec.h"
#include "calib/probe/probe_fill.h"
#include "formats/yaml_spec.h"
#include "lights/probe_sources.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <map>
#include <set>
#include <sstream>

namespace rsibr {

namespace {

nlohmann::json vec(const Vec3& v) { return nlohmann::json::array({v.x(), v.y(), v.z()}); }

Vec3 ratio(const Vec3& part, const Vec3& whole) {
  Vec3 r;
  for (int k = 0; k < 3; ++k) r[k] = whole[k] > 0 ? part[k] / whole[k] : 0.0;
  return r;
}

}  // namespace

std::shared_ptr<const Fresnel> chrome_fresnel_from_spec(const std::string& spec, const std::string& option) {
  if (spec.empty() || spec == "none") return nullptr;
  try {
    return make_fresnel(parse_yaml(spec, option), option);
  } catch (const std::exception& e) {
    throw std::invalid_argument(option + ": " + e.what());
  }
}

RecoveredProbe recover_probe_sources(const MapSet& chrome, const ProbeOptions& probe,
                                     const std::vector<GreyBallMaps>& grey, const std::vector<GlossyBallMaps>& glossy,
                                     const SourceRecoveryOptions& options, bool recover) {
  RecoveredProbe out;
  out.measured = assemble_probe(chrome, probe);
  const Probe& measured = out.measured;
  out.env = measured.env;
  out.env.pixels = measured.env.pixels.clone();
  out.regions = find_clipped_regions(measured);
  if (recover && !out.regions.empty()) {
    // The probe without each view's chrome map (the jackknife's folds), by image name.
    std::map<std::string, EnvMap> without;
    if (options.jackknife && chrome.views.size() >= 3) {
      std::vector<EnvMap> folds = assemble_probe_folds(chrome, probe);
      for (std::size_t v = 0; v < chrome.views.size(); ++v)
        if (!chrome.views[v].image.empty()) without[chrome.views[v].image] = std::move(folds[v]);
    }
    out.recovery = recover_sources(measured.env, out.regions, grey, glossy, options, without);
  }
  const std::vector<double> footprints = add_sources_to_probe(out.env, out.recovery.sources);
  const nlohmann::json sources = light_sources_json(out.recovery.sources, footprints);
  if (!out.recovery.sources.empty()) set_light_source_attributes(out.env, sources);

  const std::vector<double> integral_v = integral(measured.env);
  const Vec3 measured_integral(integral_v[0], integral_v[1], integral_v[2]);
  Vec3 recovered = Vec3::Zero(), recovered_var = Vec3::Zero(), bounds = Vec3::Zero();
  for (const LightSource& s : out.recovery.sources) recovered += s.power, recovered_var += s.power_sigma.cwiseAbs2();
  std::set<int> done;
  for (const LightSource& s : out.recovery.sources) done.insert(s.region);
  // Texels of a region nothing recovered keep the light measured there: at least the lower bound.
  out.flags = cv::Mat(measured.env.pixels.size(), CV_8UC1, cv::Scalar(0));
  for (std::size_t i = 0; i < out.regions.size(); ++i)
    for (const long t : out.regions[i].texels) {
      const int y = int(t / out.flags.cols), x = int(t % out.flags.cols);
      if (done.count(int(i))) {
        out.flags.at<uchar>(y, x) = kProbeSource;
        continue;
      }
      out.flags.at<uchar>(y, x) = kProbeLowerBound;
      cv::Vec3f& p = out.env.pixels.at<cv::Vec3f>(y, x);
      const cv::Vec3f b = measured.lower_bound.at<cv::Vec3f>(y, x);
      for (int k = 0; k < 3; ++k) p[k] = std::max(p[k], b[k]);
    }
  nlohmann::json regions = nlohmann::json::array();
  for (std::size_t i = 0; i < out.regions.size(); ++i) {
    const ClippedRegion& g = out.regions[i];
    const Vec3 d = g.direction.normalized();
    nlohmann::json rj = {{"index", i},
                         {"direction", vec(d)},
                         {"azimuth_deg", std::atan2(d.x(), d.z()) * 180 / kPi},
                         {"elevation_deg", std::asin(std::clamp(d.y(), -1.0, 1.0)) * 180 / kPi},
                         {"solid_angle_sr", g.solid_angle},
                         {"radius_deg", g.radius * 180 / kPi},
                         {"texels", g.texels.size()},
                         {"lower_bound", vec(g.lower_bound)},
                         {"recovered", done.count(int(i)) > 0}};
    if (!done.count(int(i))) bounds += g.lower_bound;
    regions.push_back(rj);
  }
  for (std::size_t k = 0; k < out.recovery.unrecovered.size() && k < out.recovery.notes.size(); ++k) {
    const int i = out.recovery.unrecovered[k];
    if (i >= 0 && std::size_t(i) < regions.size()) regions[std::size_t(i)]["note"] = out.recovery.notes[k];
  }
  if (!recover)
    for (auto& r : regions) r["note"] = "recovery off: the probe keeps its lower bound";
  nlohmann::json residuals = nlohmann::json::array();
  for (const BallResidual& b : out.recovery.residuals) {
    nlohmann::json views = nlohmann::json::array();
    for (std::size_t v = 0; v < b.views.size(); ++v)
      views.push_back({{"name", b.views[v]},
                       {"before", v < b.view_before.size() ? b.view_before[v] : 0.0},
                       {"after", v < b.view_after.size() ? b.view_after[v] : 0.0}});
    residuals.push_back({{"ball", b.ball},
                         {"kind", b.kind},
                         {"texels", b.texels},
                         {"before", b.before},
                         {"after", b.after},
                         {"views", views}});
  }
  out.summary = {{"enabled", recover},
                 {"clipped_fraction", measured.clipped_fraction},
                 {"regions", regions},
                 {"sources", sources},
                 {"notes", recover ? nlohmann::json(out.recovery.notes) : nlohmann::json::array()},
                 {"measured_integral", vec(measured_integral)},
                 {"recovered_power", vec(recovered)},
                 {"recovered_power_sigma", vec(recovered_var.cwiseSqrt())},
                 {"missing_fraction", vec(ratio(recovered, measured_integral + recovered))},
                 {"lower_bound_fraction", vec(ratio(bounds, measured_integral + bounds))},
                 {"residuals", residuals},
                 {"robust_sigma", out.recovery.robust_sigma},
                 {"texels", out.recovery.texels},
                 {"fitted_texels", out.recovery.fitted_texels}};
  return out;
}

double fill_unseen_directions(RecoveredProbe& probe, double min_weight) {
  const cv::Mat trusted = probe.measured.weight >= min_weight;
  const cv::Mat unseen = (trusted == 0) & (probe.flags == 0);
  const double filled = fill_unseen(probe.env, trusted, unseen);
  probe.flags.setTo(kProbeFilled, unseen);
  return filled;
}

void write_recovered_probe(const std::string& path, const RecoveredProbe& probe, double min_weight) {
  cv::Mat confidence = probe.measured.weight.clone();
  confidence.setTo(0, probe.measured.weight < min_weight);
  write_probe(path, probe.env, confidence, probe.flags);
}

std::string light_sources_line(const nlohmann::json& s) {
  if (!s.contains("regions") || s["regions"].empty()) return "";
  const std::size_t regions = s["regions"].size(), sources = s.value("sources", nlohmann::json::array()).size();
  std::ostringstream o;
  o << std::fixed << std::setprecision(0);
  auto pct = [&](const nlohmann::json& v) {
    std::ostringstream p;
    p << std::fixed << std::setprecision(0) << 100 * v[0].get<double>() << "% / " << 100 * v[1].get<double>() << "% / "
      << 100 * v[2].get<double>() << "% (R/G/B)";
    return p.str();
  };
  o << regions << " clipped light source" << (regions == 1 ? "" : "s")
    << " (clipped in every chrome view that saw it); ";
  if (sources > 0) {
    std::set<std::string> balls;
    for (const auto& src : s["sources"])
      for (const auto& b : src["balls"]) balls.insert(b.get<std::string>());
    std::string from;
    for (const std::string& b : balls) from += (from.empty() ? "" : ", ") + b;
    o << "recovered " << sources << " from " << (from.empty() ? "-" : from) << ": " << pct(s["missing_fraction"])
      << " of the probe's light";
    if (sources < regions)
      o << "; " << regions - sources << " not recovered (kept at their lower bounds, " << pct(s["lower_bound_fraction"])
        << " of the light)";
  } else {
    o << "none recovered: " << pct(s["lower_bound_fraction"])
      << " of the probe's light is only a lower bound (clipped in every bracket; it may be far brighter)";
  }
  return o.str();
}

}  // namespace rsibr
