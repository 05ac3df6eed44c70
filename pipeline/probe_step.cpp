#include "pipeline/probe_step.h"

#include "calib/probe/probe.h"
#include "lights/recovered_probe.h"
#include "core/resample.h"
#include "formats/exr_io.h"
#include "formats/map_set.h"
#include "pipeline/default_sizes.h"

#include <cmath>
#include <stdexcept>

namespace rsibr {

namespace fs = std::filesystem;

StepOutputs run_probe_step(const ProbeStep& s) {
  StepOutputs out;
  if (!s.given.empty()) {
    EnvMap env = resample(read_environment(s.given), Layout(LayoutKind::LatLong, s.width, s.width / 2));
    env.attributes["producer"] = "rsibr process (given probe " + fs::path(s.given).filename().string() + ")";
    write_environment(s.out.string(), env);
    out.files = {s.out};
    out.summary = {{"views", 0}, {"width", s.width}, {"covered_fraction", 1.0}, {"fresnel", "given: " + s.given}};
    return out;
  }
  MapSet all;
  for (const fs::path& p : s.chrome_maps)
    for (MapView& v : read_map_set(p.string()).views) all.views.push_back(std::move(v));
  ProbeOptions po;
  po.width = s.width;
  const auto fresnel = chrome_fresnel_from_spec(s.chrome_fresnel, "--chrome-fresnel");
  po.fresnel = fresnel.get();
  Probe p = assemble_probe(all, po);
  // A chrome ball sees most of the sphere from one view (all but the cone behind it); a probe
  // that saw almost nothing means a lens or a ball that is wrong, never a usable probe.
  if (!(p.covered_fraction >= 0.1))
    throw std::runtime_error(
        "the chrome maps saw " + std::to_string(100 * p.covered_fraction).substr(0, 4) +
        "% of the sphere (a chrome ball sees most of it): the lens (lens.cameramodel, see the lens step) or the "
        "chrome ball is wrong; give the lens with --lens FILE or the ball with --ball VIEW:BALL=X,Y,R");
  p.env.attributes["views"] = std::to_string(all.views.size());
  p.env.attributes["producer"] = "rsibr process (probe step)";
  p.env.attributes["version"] = RSIBR_VERSION;
  if (fresnel) p.env.attributes["fresnel"] = fresnel->spec();
  write_environment(s.out.string(), p.env);
  out.files = {s.out};
  // Seen well: a summed confidence of at least one half (one view's centre to mid-disc; behind
  // the ball a lone view sees only its stretched rim, where the confidence fades to 0).
  double well = 0, all_sa = 0;
  for (int y = 0; y < p.weight.rows; ++y) {
    const double sa = std::cos((0.5 - (y + 0.5) / p.weight.rows) * kPi);
    for (int x = 0; x < p.weight.cols; ++x) {
      all_sa += sa;
      if (p.weight.at<float>(y, x) >= 0.5f) well += sa;
    }
  }
  out.summary = {{"views", all.views.size()},
                 {"width", s.width},
                 {"memory_mb", double(probe_bytes(s.width)) / (1 << 20)},
                 {"covered_fraction", p.covered_fraction},
                 {"well_seen_fraction", all_sa > 0 ? well / all_sa : 0.0},
                 {"clipped_fraction", p.clipped_fraction},
                 {"fresnel", fresnel ? fresnel->spec() : "none (the probe holds F L)"}};
  return out;
}

}  // namespace rsibr
