#include "pipeline/bake_step.h"

#include "bake/brdf_spec.h"
#include "bake/integrator.h"
#include "bake/map_set_bake.h"
#include "formats/exr_io.h"
#include "formats/map_set.h"
#include "plan/bake_plan.h"

#include <algorithm>
#include <iomanip>
#include <sstream>
#include <stdexcept>

namespace rsibr {

StepOutputs run_bake_step(const BakeStep& s) {
  StepOutputs out;
  const EnvMap probe = read_environment(s.probe.string());
  std::ostringstream spec;
  spec << std::setprecision(9) << "{type: lambert, albedo: [" << s.albedo << ", " << s.albedo << ", " << s.albedo
       << "]}";
  const auto brdf = parse_brdf(spec.str());
  std::string method = s.method;
  MapSetBakeOptions bo;
  bo.integrator.samples = s.samples;
  nlohmann::json planned;
  // Planned with the bake's own seed: a filtered-importance bake's error depends on it.
  if (s.max_error > 0) {
    const IntegratorPlan plan = plan_integrator(probe, *brdf, s.max_error, default_integrator_settings(), s.seed);
    if (!plan.chosen)
      throw std::runtime_error("no integrator is predicted to reach --max-error " + std::to_string(s.max_error) +
                               " on " + s.probe.filename().string());
    method = plan.chosen->setting.method;
    bo.integrator.samples = std::max(1, plan.chosen->setting.samples);
    bo.integrator.reference_width = plan.chosen->setting.reference_width;
    planned = plan.to_json();
    if (s.log)
      s.log("bake: planned " + plan.chosen->setting.label() + " (" + std::to_string(100 * plan.chosen->error) +
            "% at the pilot texels)");
  }
  const auto integrator = make_integrator(method, probe);
  bo.integrator.seed = s.seed;
  bo.environment_name = s.probe.filename().string();
  nlohmann::json balls = nlohmann::json::array();
  for (const BakeGreyBall& b : s.balls) {
    const MapSet captured = read_map_set(b.captured.string());
    // At the captured maps' own frames and size, so the comparison is texel for texel.
    std::vector<BakeFrame> frames;
    for (const MapView& cv : captured.views) frames.push_back({cv.view, cv.world_from_view});
    bo.res = captured.width();
    MapSet computed = bake_map_set(*brdf, *integrator, frames, bo);
    for (std::size_t i = 0; i < computed.views.size(); ++i) computed.views[i].image = captured.views[i].image;
    write_map_set(b.computed.string(), computed);
    out.files.push_back(b.computed);
    balls.push_back({{"ball", b.name}, {"views", computed.views.size()}});
  }
  out.summary = {{"material", brdf->spec()}, {"balls", balls}, {"method", method}};
  if (!planned.is_null()) out.summary["plan"] = planned;
  return out;
}

}  // namespace rsibr
