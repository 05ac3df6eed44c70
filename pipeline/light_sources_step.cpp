#include "pipeline/light_sources_step.h"

#include "bake/brdf_spec.h"
#include "formats/exr_io.h"
#include "formats/map_set.h"
#include "lights/recovered_probe.h"

namespace rsibr {

nlohmann::json run_light_sources_step(const LightSourcesStep& s) {
  if (s.given_probe) {
    EnvMap env = read_environment(s.measured.string());
    write_environment(s.out.string(), env);
    return {{"enabled", false},
            {"given", true},
            {"regions", nlohmann::json::array()},
            {"sources", nlohmann::json::array()},
            {"notes", {"the probe is a given environment: nothing was clipped"}}};
  }
  MapSet chrome;
  for (const auto& p : s.chrome)
    for (MapView& v : read_map_set(p.string()).views) chrome.views.push_back(std::move(v));
  const auto fresnel = chrome_fresnel_from_spec(s.chrome_fresnel, "--chrome-fresnel");
  ProbeOptions po;
  po.width = s.probe_width;
  po.fresnel = fresnel.get();
  std::vector<MapSet> grey_sets, glossy_sets;
  grey_sets.reserve(s.grey.size());
  glossy_sets.reserve(s.glossy.size());
  std::vector<GreyBallMaps> grey;
  std::vector<GlossyBallMaps> glossy;
  for (const auto& [name, path] : s.grey) {
    grey_sets.push_back(read_map_set(path.string()));
    grey.push_back({name, &grey_sets.back(), Vec3::Constant(s.grey_albedo)});
  }
  std::unique_ptr<Brdf> brdf;
  if (!s.glossy_brdf.empty() && !s.glossy.empty()) {
    brdf = parse_brdf(s.glossy_brdf);
    for (const auto& [name, path] : s.glossy) {
      glossy_sets.push_back(read_map_set(path.string()));
      glossy.push_back({name, &glossy_sets.back(), brdf.get()});
    }
  }
  SourceRecoveryOptions ro;
  ro.seed = s.seed;
  RecoveredProbe r = recover_probe_sources(chrome, po, grey, glossy, ro, s.recover);
  // Directions no view saw, filled so a renderer can use the probe (calib/probe/probe_fill.h); they keep
  // zero confidence and the kProbeFilled flag.
  const double filled = s.fill ? fill_unseen_directions(r, po.min_weight) : 0.0;
  r.env.attributes["views"] = std::to_string(chrome.views.size());
  r.env.attributes["producer"] = "rsibr process (sources step)";
  r.env.attributes["version"] = RSIBR_VERSION;
  r.env.attributes["filled"] = s.fill ? "push-pull of log radiance (flags channel: 4)" : "none (0)";
  if (fresnel) r.env.attributes["fresnel"] = fresnel->spec();
  write_recovered_probe(s.out.string(), r, po.min_weight);
  r.summary["filled_fraction"] = filled;
  r.summary["fill"] = s.fill ? "push-pull" : "none";
  r.summary["glossy_used"] = !glossy.empty();
  if (!s.glossy.empty() && s.glossy_brdf.empty())
    r.summary["notes"].push_back("glossy ball(s) not used: their BRDF is not known (--glossy-brdf)");
  return r.summary;
}

}  // namespace rsibr
