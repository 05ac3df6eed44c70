// rsibr blend: the radiance map for any view from a map set (the runtime's warp and blend), written
// as a one-view map set whose confidence channel is the blend's total weight.
#include "cli/bake_planning.h"
#include "formats/file_error.h"
#include "cli/summary.h"
#include "cli/verbs.h"

#include "formats/atomic_file.h"
#include "core/colour.h"
#include "formats/map_set.h"
#include "formats/output_plan.h"
#include "core/preview_exposure.h"
#include "runtime/blend.h"
#include "runtime/make_warp.h"
#include "plan/warp_plan.h"

#include "formats/image_codecs.h"

#include <chrono>
#include <iostream>
#include <filesystem>
#include <memory>
#include <optional>

namespace rsibr::cli {
namespace {

struct BlendArgs {
  std::string maps, output, warp = "precomputed", preview, json;
  std::string max_error;  // empty: --warp as given; else the fastest warp within this error (plan/warp_plan.h)
  std::vector<double> view{0, 0, 1}, up{0, 1, 0};
  int size = 0;
  int rings = 16;
  int table = 0;
  double rim_fade = 0.4;
  std::optional<float> preview_exposure;  // nullopt: metered (core/preview_exposure.h)
  bool sanitize = false;
};

int run_blend(const BlendArgs& a) {
  OutputPlan outputs({a.maps});
  const std::string exr = outputs.file(a.output), preview = outputs.file(a.preview), json = outputs.file(a.json);
  long sanitized = 0;
  const MapSet set = read_map_set(a.maps, a.sanitize ? BadTexels::zero : BadTexels::refuse, &sanitized);
  const ViewSet views = set.view_set();
  const Vec3 view(a.view[0], a.view[1], a.view[2]), up(a.up[0], a.up[1], a.up[2]);
  if (!view.allFinite() || !(view.norm() > 0)) throw std::invalid_argument("--view must be a non-zero direction");
  const int w = a.size > 0 ? a.size : set.width(), h = a.size > 0 ? a.size : set.height();
  BlendOptions options;
  options.width = w;
  options.height = h;
  options.rim_fade = a.rim_fade;
  WarpSettings warp_settings{a.warp, a.rings, axis_in_views(set, up), a.table};
  std::optional<WarpPlan> warp_plan;
  if (!a.max_error.empty()) {
    try {
      warp_plan = plan_warp(set, views, view, up, w, h, parse_error_budget(a.max_error),
                            default_warp_candidates(warp_settings.axis), options);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(a.maps + ": " + e.what());
    }
    warp_settings = warp_plan->chosen.warp;
    std::cerr << "rsibr blend: --max-error " << a.max_error << ": the " << warp_settings.name << " warp"
              << (warp_settings.name == "tessellated" ? " (" + std::to_string(warp_settings.rings) + " rings)" : "")
              << ", " << 100 * warp_plan->chosen.error << "% from the exact warp, " << 1e3 * warp_plan->chosen.seconds
              << " ms\n";
  }
  const std::unique_ptr<Warp> warp = make_warp(warp_settings, w, h);
  options.warp = warp.get();
  const auto t0 = std::chrono::steady_clock::now();
  BlendResult r;
  try {
    r = blend(set, views, view, up, options);
  } catch (const std::invalid_argument& e) {  // a property of the map set (its size, its views)
    throw std::invalid_argument(a.maps + ": " + e.what());
  }
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  MapSet out;
  MapView mv;
  mv.view = view.normalized();
  mv.world_from_view = r.world_from_view;
  const MapView& first = set.views[std::size_t(r.located.views[0])];
  mv.warp = first.warp;
  mv.source = first.source;
  mv.material = first.material;
  mv.attributes["version"] = RSIBR_VERSION;
  mv.attributes["blendOf"] = std::filesystem::path(a.maps).filename().string();
  std::string sources;
  for (int i = 0; i < r.located.count; ++i)
    sources += (i ? " " : "") + std::to_string(r.located.views[std::size_t(i)]) + ":" +
               std::to_string(r.located.weights[std::size_t(i)]);
  mv.attributes["blendSources"] = sources;
  mv.rgb = r.rgb;
  mv.confidence = r.weight;
  out.views.push_back(mv);
  write_map_set(exr, out);
  if (!preview.empty() &&
      !write_image(preview, display_encode(r.rgb, a.preview_exposure ? *a.preview_exposure : preview_exposure(r.rgb))))
    throw FileError(a.preview, "cannot write the preview image", {}, FileRole::Output);
  nlohmann::json j;
  j["maps"] = a.maps;
  j["output"] = a.output;
  j["view"] = {mv.view.x(), mv.view.y(), mv.view.z()};
  j["inside_view_set"] = r.located.inside;
  j["distance_to_view_set_rad"] = r.located.distance;
  j["sources"] = nlohmann::json::array();
  for (int i = 0; i < r.located.count; ++i)
    j["sources"].push_back({{"view", r.located.views[std::size_t(i)]}, {"weight", r.located.weights[std::size_t(i)]}});
  j["warp"] = warp_settings.name;
  if (warp_plan) j["warp_plan"] = warp_plan->to_json();
  j["seconds"] = secs;
  j["values_sanitized"] = sanitized;
  write_summary(json, j);
  outputs.commit();
  return 0;
}

}  // namespace

Runner add_blend(CLI::App& app) {
  auto a = std::make_shared<BlendArgs>();
  CLI::App* c = app.add_subcommand("blend", "Warp and blend a map set to the radiance map of any view");
  c->footer(
      "Finds the view's triangle in the map set's view set, warps its three maps in reflection space "
      "(each with its own mirror or normal warp), fades each near its singularity and normalises per "
      "texel. The output is a one-view map set; its confidence channel is the blend's total weight.\n"
      "Example: rsibr blend maps.exr novel.exr --view 0.3 0.5 0.8 --preview novel.png");
  c->add_option("maps", a->maps, "Map set (.exr)")->required();
  c->add_option("output", a->output, "Output one-view map set (.exr)")->required();
  c->add_option("--view", a->view, "View direction (world, toward the viewer)")->expected(3);
  c->add_option("--up", a->up, "Up hint for the view frame (world)")->expected(3);
  c->add_option("--size", a->size, "Output map size (default: the map set's)")->check(CLI::Range(2, 8192));
  c->add_option("--warp", a->warp,
                "exact, precomputed (per-texel directions cached; same result), tessellated (the paper's mesh: "
                "vertices warped exactly, texture coordinates interpolated) or double-indirection (a screen table "
                "and a parametric table; a rotation about --up, as between views of one ring or turntable, is an "
                "offset into them)");
  c->add_option("--rings", a->rings, "tessellated: rings of the disc mesh (4x as many segments)")
      ->check(CLI::Range(1, 1024));
  c->add_option("--table", a->table,
                "double-indirection: columns of the parametric table (half as many rows; "
                "default: the map width)")
      ->check(CLI::Range(3, 4096));
  c->add_option("--max-error", a->max_error,
                "Choose the fastest warp whose map is within this relative RMS (e.g. 1%) of the exact warp's, "
                "measured at this view (instead of --warp); the measurements go in --json")
      ->check(error_budget_check())
      ->excludes("--warp")
      ->excludes("--rings")
      ->excludes("--table");
  c->add_option("--rim-fade", a->rim_fade, "Width of the singularity fade (0 disables)")->check(CLI::Range(0.0, 1.0));
  c->add_option("--preview", a->preview, "Also write a display-encoded PNG");
  c->add_option("--preview-exposure", a->preview_exposure,
                "Exposure of the preview in stops (default: the median luminance at mid-grey)");
  c->add_flag("--sanitize", a->sanitize,
              "Zero NaN, Inf and absurd (> 1e30) values of the map sets (and clamp their "
              "confidences to [0, 1]) instead of failing; the JSON counts them");
  c->add_option("--json", a->json, "Write a JSON summary to FILE ('-' for stdout)");
  return [a] { return run_blend(*a); };
}

}  // namespace rsibr::cli
