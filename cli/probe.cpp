// rsibr probe: captured chrome-ball maps (rsibr extract outputs, one world frame) blended by their
// confidences into one lat-long light probe (calib/probe/probe.h).
#include "cli/summary.h"
#include "cli/verbs.h"

#include "bake/brdf_spec.h"
#include "calib/probe/probe.h"
#include "formats/atomic_file.h"
#include "formats/exr_io.h"
#include "formats/map_set.h"
#include "formats/output_plan.h"
#include "formats/yaml_spec.h"
#include "lights/recovered_probe.h"

#include <yaml-cpp/yaml.h>

#include <iostream>

namespace rsibr::cli {
namespace {

struct ProbeArgs {
  std::vector<std::string> maps, grey, glossy;
  std::string out, fresnel = kDefaultChromeFresnel, json, glossy_brdf;
  double grey_albedo = 0.18;
  int width = 512;
  bool quiet = false, sanitize = false, fill = true;
};

// Captured normal-warp map sets (grey or glossy balls) for the source recovery.
MapSet read_ball_maps(const std::string& path, const std::string& option) {
  MapSet s = read_map_set(path);
  for (std::size_t v = 0; v < s.views.size(); ++v)
    if (s.views[v].confidence.empty() || s.views[v].source != MapSource::Captured ||
        s.views[v].warp != CentralDirection::Normal)
      throw std::invalid_argument(path + ": view." + std::to_string(v) + " is not a captured grey or glossy map (" +
                                  option + ")");
  return s;
}

int run_probe(const ProbeArgs& a) {
  std::vector<std::filesystem::path> inputs(a.maps.begin(), a.maps.end());
  inputs.insert(inputs.end(), a.grey.begin(), a.grey.end());
  inputs.insert(inputs.end(), a.glossy.begin(), a.glossy.end());
  OutputPlan outputs(inputs);
  const std::string exr = outputs.file(a.out), json = outputs.file(a.json);
  const std::shared_ptr<const Fresnel> fresnel = chrome_fresnel_from_spec(a.fresnel, "--fresnel");
  if (!a.glossy.empty() && a.glossy_brdf.empty())
    throw std::invalid_argument("--glossy: needs --glossy-brdf (the glossy ball's BRDF)");
  std::unique_ptr<Brdf> glossy_brdf;
  if (!a.glossy_brdf.empty()) {
    try {
      glossy_brdf = parse_brdf(a.glossy_brdf);
    } catch (const std::exception& e) {
      throw std::invalid_argument(std::string("--glossy-brdf: ") + e.what());
    }
  }
  MapSet all;
  long sanitized = 0;
  for (const std::string& path : a.maps) {
    long zeroed = 0;
    const MapSet s = read_map_set(path, a.sanitize ? BadTexels::zero : BadTexels::refuse, &zeroed);
    sanitized += zeroed;
    for (std::size_t v = 0; v < s.views.size(); ++v) {
      const MapView& mv = s.views[v];
      if (mv.confidence.empty() || mv.source != MapSource::Captured)
        throw std::invalid_argument(path + ": view." + std::to_string(v) +
                                    " is not a captured map (no confidence channel)");
      if (!all.views.empty() && (mv.rgb.size() != all.views.front().rgb.size()))
        throw std::invalid_argument(path + ": maps are " + std::to_string(mv.rgb.cols) + "x" +
                                    std::to_string(mv.rgb.rows) + " but the first input's are " +
                                    std::to_string(all.views.front().rgb.cols) + "x" +
                                    std::to_string(all.views.front().rgb.rows));
      all.views.push_back(mv);
    }
  }
  // Maps extracted without a pose are each in their own camera's frame: they cannot be blended.
  for (std::size_t v = 0; v < all.views.size() && all.views.size() > 1; ++v) {
    const auto frame = all.views[v].attributes.find("frame");
    if (frame != all.views[v].attributes.end() && frame->second.rfind("camera", 0) == 0)
      throw std::invalid_argument(
          (!all.views[v].image.empty() ? all.views[v].image : "view " + std::to_string(v)) +
          ": extracted in its camera's frame (no pose); blending views needs their world orientations");
  }
  std::vector<MapSet> ball_sets;
  ball_sets.reserve(a.grey.size() + a.glossy.size());
  std::vector<GreyBallMaps> grey;
  std::vector<GlossyBallMaps> glossy;
  for (const std::string& g : a.grey) {
    ball_sets.push_back(read_ball_maps(g, "--grey"));
    grey.push_back({std::filesystem::path(g).stem().string(), &ball_sets.back(), Vec3::Constant(a.grey_albedo)});
  }
  for (const std::string& g : a.glossy) {
    ball_sets.push_back(read_ball_maps(g, "--glossy"));
    glossy.push_back({std::filesystem::path(g).stem().string(), &ball_sets.back(), glossy_brdf.get()});
  }
  ProbeOptions o;
  o.width = a.width;
  o.fresnel = fresnel.get();
  // Light clipped in every view is recovered when a grey or glossy ball's maps are given.
  RecoveredProbe rp =
      recover_probe_sources(all, o, grey, glossy, SourceRecoveryOptions{}, !grey.empty() || !glossy.empty());
  const Probe& p = rp.measured;
  const double filled = a.fill ? fill_unseen_directions(rp, o.min_weight) : 0.0;
  rp.env.attributes["views"] = std::to_string(all.views.size());
  if (a.fill) rp.env.attributes["filled"] = "push-pull of log radiance (flags channel: 4)";
  if (fresnel) rp.env.attributes["fresnel"] = fresnel->spec();
  write_recovered_probe(exr, rp, o.min_weight);
  nlohmann::json j;
  j["maps"] = a.maps;
  j["out"] = a.out;
  j["views"] = all.views.size();
  j["width"] = a.width;
  j["covered_fraction"] = p.covered_fraction;
  j["filled_fraction"] = filled;
  j["values_sanitized"] = sanitized;
  j["fresnel"] = fresnel ? fresnel->spec() : "none";
  j["light_sources"] = rp.summary;
  write_summary(json, j);
  outputs.commit();
  if (!a.quiet && a.json != "-") {
    std::cerr << all.views.size() << " views -> " << a.out << " (" << 100 * p.covered_fraction << "% of the sphere)\n";
    const std::string line = light_sources_line(rp.summary);
    if (!line.empty()) std::cerr << "probe: " << line << "\n";
    if (!rp.regions.empty() && grey.empty() && glossy.empty())
      std::cerr << "probe: give the grey ball's maps (--grey) to recover the clipped light\n";
  }
  return 0;
}

}  // namespace

Runner add_probe(CLI::App& app) {
  auto a = std::make_shared<ProbeArgs>();
  CLI::App* c = app.add_subcommand("probe", "Blend captured chrome-ball maps into one lat-long light probe");
  c->footer(
      "Every view of the inputs (rsibr extract outputs in one world frame) is looked up at each direction through "
      "its mirror mapping and weighted by its confidence channel, so the camera, photographer and stretched rim of "
      "one view are replaced by the others. --fresnel divides out the ball's reflectance (a Fresnel spec as in "
      "rsibr bake; default: chrome, '" +
      std::string(kDefaultChromeFresnel) +
      "', about 57% at normal incidence; "
      "'none' keeps F L). Directions no view saw (behind the ball, the masked camera) are filled from their "
      "surroundings (a push-pull of log radiance; --no-fill leaves them 0). Directions clipped in every bracket of "
      "every view that saw them (a sun) keep the largest clipped value, a lower bound: with --grey (a grey ball's "
      "captured maps in the same world frame) each such region is recovered as a compact source from the grey "
      "ball's shading (and a glossy ball's with --glossy and --glossy-brdf) and written into the probe, listed in "
      "its header (rsibr.lightSources) and --json. The output's `confidence` channel is the views' summed "
      "confidence (0 where nothing was measured) and its `flags` channel 1 for a lower bound, 2 for a recovered "
      "source, 4 for a filled texel.\n"
      "Example: rsibr probe north.exr south.exr east.exr --out probe.exr --fresnel '{type: schlick, f0: [0.6, 0.6, 0.6]}'");
  c->add_option("maps", a->maps, "Captured map sets (chrome)")->required();
  c->add_option("--out", a->out, "Output lat-long EXR")->required();
  c->add_option("--width", a->width, "Lat-long width (height = width / 2)")->check(CLI::Range(4, 16384));
  c->add_option("--fresnel", a->fresnel, "The ball's Fresnel spec (divided out; 'none': the probe holds F L)")
      ->capture_default_str();
  c->add_option("--grey", a->grey, "Captured grey-ball map sets: recover the clipped light from them");
  c->add_option("--grey-albedo", a->grey_albedo, "The grey ball's albedo")
      ->check(CLI::Range(0.001, 1.0))
      ->capture_default_str();
  c->add_option("--glossy", a->glossy,
                "Captured glossy-ball map sets (with --glossy-brdf): they constrain the sources too");
  c->add_option("--glossy-brdf", a->glossy_brdf, "The glossy ball's BRDF spec (YAML text)");
  c->add_option("--json", a->json, "Write a JSON summary to FILE ('-' for stdout)");
  c->add_flag("--sanitize", a->sanitize,
              "Zero NaN, Inf and absurd (> 1e30) values of the map sets (and clamp their "
              "confidences to [0, 1]) instead of failing; the JSON counts them");
  c->add_flag("!--no-fill", a->fill, "Leave the directions no view saw at 0 (with confidence 0, flags 0)");
  c->add_flag("-q,--quiet", a->quiet, "No report line");
  return [a] { return run_probe(*a); };
}

}  // namespace rsibr::cli
