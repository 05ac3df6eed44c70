// rsibr pattern: analytic test environments (known integrals) in any layout.
#include "cli/option_checks.h"
#include "cli/summary.h"
#include "cli/verbs.h"

#include "formats/atomic_file.h"
#include "formats/exr_io.h"
#include "formats/map_set.h"
#include "formats/output_plan.h"
#include "core/patterns.h"
#include "core/texel_audit.h"

#include <cmath>
#include <iostream>
#include <memory>

namespace rsibr::cli {
namespace {

struct PatternArgs {
  std::string kind = "direction", to = "latlong", output, json, views;
  int size = 256;
  double sun_intensity = 1e5, sun_radius_deg = 0.27, checker_deg = 10;
  std::vector<double> sun_dir{0.3, 0.6, -0.5};
  int subsamples = 4;
};

int run_pattern(const PatternArgs& a) {
  OutputPlan outputs({a.views});
  const std::string exr = outputs.file(a.output), json = outputs.file(a.json);
  Radiance f;
  if (a.kind == "direction") {
    f = patterns::direction_coded();
  } else if (a.kind == "white") {
    f = patterns::constant(Vec3(1, 1, 1));
  } else if (a.kind == "checker") {
    f = patterns::latlong_checker(a.checker_deg);
  } else if (a.kind == "sun-sky") {
    const Vec3 sun(a.sun_dir[0], a.sun_dir[1], a.sun_dir[2]);
    if (!(sun.norm() > 0)) throw std::invalid_argument("--sun-dir must not be zero");
    f = patterns::sun_and_sky(sun, a.sun_radius_deg * kPi / 180, Vec3::Constant(a.sun_intensity), Vec3(0.25, 0.45, 1.0),
                              Vec3(0.9, 0.9, 0.85));
  } else {
    throw std::invalid_argument("unknown pattern '" + a.kind + "' (direction, white, checker, sun-sky)");
  }
  if (!a.views.empty()) {
    // A computed map set of a perfect mirror without Fresnel: view independent, so any view's map
    // is exactly known. Texel p of view v holds L(T_v g_mirror(p)); the sphere layout's direction
    // is g_mirror in the view frame, so each map is the pattern rotated into that frame.
    const ViewSet set = ViewSet::named(a.views);
    const Layout sphere = Layout::with_size(LayoutKind::Sphere, a.size);
    MapSet maps;
    for (const Vec3& v : set.views()) {
      MapView mv;
      mv.view = v;
      mv.world_from_view = world_from_view_for(v);
      mv.warp = CentralDirection::Mirror;
      mv.source = MapSource::Computed;
      mv.material = "type: mirror  # perfect mirror, no Fresnel (rsibr pattern " + a.kind + ")";
      mv.attributes["version"] = RSIBR_VERSION;
      const Mat3 T = mv.world_from_view;
      mv.rgb = render_pattern([&](const Vec3& d) { return f(T * d); }, sphere, a.subsamples).pixels;
      maps.views.push_back(std::move(mv));
    }
    write_map_set(exr, maps);
    nlohmann::json j;
    j["output"] = a.output;
    j["pattern"] = a.kind;
    j["views"] = maps.views.size();
    j["size"] = a.size;
    write_summary(json, j);
    outputs.commit();
    return 0;
  }
  const Layout layout = Layout::with_size(parse_layout_kind(a.to), a.size);
  int m = a.subsamples;
  if (a.kind == "sun-sky") {
    // Enough points per texel that the sun's disc is hit about three times across.
    const double texel = std::sqrt(4 * kPi / double(layout.texel_count()));
    m = std::max(m, std::min(64, int(std::ceil(3 * texel / (2 * a.sun_radius_deg * kPi / 180)))));
  }
  EnvMap map = render_pattern(f, layout, m);
  map.attributes["version"] = RSIBR_VERSION;
  map.attributes["command"] = "rsibr pattern " + a.kind + " --to " + a.to + " --size " + std::to_string(a.size);
  write_environment(exr, map);
  const auto integ = integral(map);
  nlohmann::json j;
  j["output"] = a.output;
  j["pattern"] = a.kind;
  j["layout"] = a.to;
  j["width"] = map.layout.width();
  j["height"] = map.layout.height();
  j["integral_rgb"] = integ;
  write_summary(json, j);
  outputs.commit();
  return 0;
}

}  // namespace

Runner add_pattern(CLI::App& app) {
  auto a = std::make_shared<PatternArgs>();
  CLI::App* c = app.add_subcommand("pattern", "Write an analytic test environment in any layout");
  c->footer(
      "Patterns: direction (RGB = (d+1)/2, integral 2*pi per channel), white (L = 1, integral 4*pi), "
      "checker (lat-long squares), sun-sky (a disc sun over a sky gradient). Texels are area averages.");
  c->add_option("pattern", a->kind, "direction, white, checker or sun-sky")->required();
  c->add_option("output", a->output, "Output .exr")->required();
  c->add_option("--to", a->to, "Layout: latlong, cube, octahedral or sphere");
  c->add_option("--size", a->size, "Layout size (lat-long width, cube face, square side)")->check(CLI::Range(2, 16384));
  c->add_option("--subsamples", a->subsamples, "n x n points per texel")->check(CLI::Range(1, 64));
  c->add_option("--sun-intensity", a->sun_intensity,
                "sun-sky: sun radiance (up to 1e30, the largest value a map may hold)")
      ->check(number_from_to(0.0, double(kMaxRadiance)));
  c->add_option("--sun-radius", a->sun_radius_deg, "sun-sky: sun angular radius in degrees")
      ->check(CLI::Range(1e-4, 90.0));
  c->add_option("--sun-dir", a->sun_dir, "sun-sky: direction toward the sun (world, +Y up)")->expected(3);
  c->add_option("--checker", a->checker_deg, "checker: square size in degrees")->check(CLI::Range(0.01, 180.0));
  c->add_option("--map-set", a->views,
                "Write instead a map set of a perfect mirror (no Fresnel) lit by the pattern, one sphere map per view "
                "of this view set (tetra, octa, icosa, 42, 162, 642, fibN or a file of 'x y z' lines)");
  c->add_option("--json", a->json, "Write a JSON summary to FILE ('-' for stdout)");
  return [a] { return run_pattern(*a); };
}

}  // namespace rsibr::cli
