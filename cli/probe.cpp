// rsibr probe: captured chrome-ball maps (rsibr extract outputs, one world frame) blended by their
// confidences into one lat-long light probe (calib/probe.h).
#include "cli/summary.h"
#include "cli/verbs.h"

#include "bake/brdf_spec.h"
#include "calib/probe.h"
#include "core/atomic_file.h"
#include "core/exr_io.h"
#include "core/map_set.h"
#include "core/output_plan.h"
#include "core/yaml_spec.h"

#include <yaml-cpp/yaml.h>

#include <iostream>

namespace rsibr::cli {
namespace {

struct ProbeArgs {
  std::vector<std::string> maps;
  std::string out, fresnel, json;
  int width = 512;
  bool quiet = false, sanitize = false;
};

int run_probe(const ProbeArgs& a) {
  std::vector<std::filesystem::path> inputs(a.maps.begin(), a.maps.end());
  OutputPlan outputs(inputs);
  const std::string exr = outputs.file(a.out), json = outputs.file(a.json);
  std::shared_ptr<const Fresnel> fresnel;
  if (!a.fresnel.empty()) {
    try {
      fresnel = make_fresnel(parse_yaml(a.fresnel, "--fresnel"), "--fresnel");
    } catch (const std::exception& e) {
      throw std::invalid_argument(std::string("--fresnel: ") + e.what());
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
      if (mv.confidence.empty() || mv.source != "captured")
        throw std::invalid_argument(path + ": view." + std::to_string(v) + " is not a captured map (no confidence channel)");
      if (!all.views.empty() && (mv.rgb.size() != all.views.front().rgb.size()))
        throw std::invalid_argument(path + ": maps are " + std::to_string(mv.rgb.cols) + "x" + std::to_string(mv.rgb.rows) +
                                    " but the first input's are " + std::to_string(all.views.front().rgb.cols) + "x" +
                                    std::to_string(all.views.front().rgb.rows));
      all.views.push_back(mv);
    }
  }
  // Maps extracted without a pose are each in their own camera's frame: they cannot be blended.
  for (std::size_t v = 0; v < all.views.size() && all.views.size() > 1; ++v) {
    const auto frame = all.views[v].attributes.find("frame");
    if (frame != all.views[v].attributes.end() && frame->second.rfind("camera", 0) == 0)
      throw std::invalid_argument(
          (all.views[v].attributes.count("image") ? all.views[v].attributes.at("image") : "view " + std::to_string(v)) +
          ": extracted in its camera's frame (no pose); blending views needs their world orientations");
  }
  ProbeOptions o;
  o.width = a.width;
  o.fresnel = fresnel.get();
  Probe p = assemble_probe(all, o);
  p.env.attributes["views"] = std::to_string(all.views.size());
  if (fresnel) p.env.attributes["fresnel"] = fresnel->spec();
  write_environment(exr, p.env);
  nlohmann::json j;
  j["maps"] = a.maps;
  j["out"] = a.out;
  j["views"] = all.views.size();
  j["width"] = a.width;
  j["covered_fraction"] = p.covered_fraction;
  j["values_sanitized"] = sanitized;
  j["fresnel"] = fresnel ? fresnel->spec() : "none";
  write_summary(json, j);
  outputs.commit();
  if (!a.quiet && a.json != "-")
    std::cerr << all.views.size() << " views -> " << a.out << " (" << 100 * p.covered_fraction << "% of the sphere)\n";
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
      "rsibr bake, e.g. '{type: conductor, eta: [2.9, 2.9, 2.6], k: [3.4, 3.4, 3.2]}'). Directions no view saw are 0.\n"
      "Example: rsibr probe north.exr south.exr east.exr --out probe.exr --fresnel '{type: schlick, f0: [0.6, 0.6, 0.6]}'");
  c->add_option("maps", a->maps, "Captured map sets (chrome)")->required();
  c->add_option("--out", a->out, "Output lat-long EXR")->required();
  c->add_option("--width", a->width, "Lat-long width (height = width / 2)")->check(CLI::Range(4, 16384));
  c->add_option("--fresnel", a->fresnel, "The ball's Fresnel spec (divided out)");
  c->add_option("--json", a->json, "Write a JSON summary to FILE ('-' for stdout)");
  c->add_flag("--sanitize", a->sanitize, "Zero NaN, Inf and absurd (> 1e30) values of the map sets (and clamp their "
                                         "confidences to [0, 1]) instead of failing; the JSON counts them");
  c->add_flag("-q,--quiet", a->quiet, "No report line");
  return [a] { return run_probe(*a); };
}

}  // namespace rsibr::cli
