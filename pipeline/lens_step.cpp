#include "pipeline/lens_step.h"

#include "calib/outline_focal.h"
#include "calib/view_image.h"

#include <cmath>

namespace rsibr {

nlohmann::json run_lens_step(const LensStep& s) {
  const LensModel lens = LensModel::read(s.calibrated);
  const double f0 = lens.intrinsics().at(0);
  nlohmann::json j = {{"source", s.source}, {"prior_focal_px", f0}};
  auto keep = [&](const std::string& why) {
    lens.write(s.out);
    j.update({{"refined", false}, {"why", why}, {"focal_px", f0}});
    return j;
  };
  // No focal length in the metadata: the outlines alone must give it, over a wide range.
  const bool outlines_only = s.source == "outlines";
  auto unknown = [&](const std::string& why) -> nlohmann::json {
    throw std::invalid_argument("lens: the photos' metadata has no focal length and " + why +
                                "; give the lens with --lens FILE (a .cameramodel, e.g. from rsibr calibrate)");
  };
  if (!s.refine)
    return outlines_only ? unknown("--no-self-calibration keeps the balls from measuring it")
                         : keep("off (--no-self-calibration)");
  if (s.source != "exif" && s.source != "lensfun" && !outlines_only)
    return keep("the lens was measured (" + s.source + ")");
  if (!outlines_only && !(s.prior_sigma_relative > 0)) return keep("the calibrate step states no uncertainty");
  const double s0 = outlines_only ? 0.0 : s.prior_sigma_relative * f0;
  if (!outlines_only) j["prior_sigma_px"] = s0;

  // The listed balls of every view, located with the metadata's lens; cut balls and points off
  // their robust cone are left out (calib/outline_focal.h drops the rest).
  std::vector<std::vector<Vec2>> outlines;
  nlohmann::json found = nlohmann::json::array();
  for (std::size_t v = 0; v < s.views.size(); ++v) {
    const ViewImage image = read_view_image(s.merged[v].string());
    const ViewCandidates vc = view_candidates(image.radiance, lens, s.balls);
    for (std::size_t b = 0; b < s.balls.size(); ++b) {
      const int pick = vc.pick[b];
      if (pick < 0) continue;
      const BallCandidate& cand = vc.cands[std::size_t(pick)];
      if (cand.cut) continue;
      std::vector<Vec2> pts;
      for (std::size_t i = 0; i < cand.loc.outline_px.size() && i < cand.loc.fit.residual_px.size(); ++i)
        if (std::abs(cand.loc.fit.residual_px[i]) < 1.0) pts.push_back(cand.loc.outline_px[i]);
      outlines.push_back(pts);
      found.push_back({{"view", s.views[v]},
                       {"ball", s.balls[b].name},
                       {"centre_px", {cand.loc.centre_px.x(), cand.loc.centre_px.y()}},
                       {"radius_px", cand.loc.radius_px}});
    }
  }
  if (outlines.empty())
    return outlines_only ? unknown("no ball outline was found to measure it with")
                         : keep("no ball outline found to refine the focal length with");
  OutlineFocal of;
  OutlineFocalOptions fo;
  if (outlines_only) {
    fo.min_scale = 0.25;  // from a fisheye-like 11 mm to a 170 mm equivalent around the 43 mm guess
    fo.max_scale = 4;
    fo.grid = 41;
  }
  try {
    of = focal_from_outlines(outlines, lens, fo);
  } catch (const std::invalid_argument& e) {
    return outlines_only ? unknown(e.what()) : keep(e.what());
  }
  std::string left_out;
  for (std::size_t i = 0; i < found.size(); ++i) {
    const OutlineFocalBall& b = of.balls[i];
    found[i].update({{"focal_px", b.focal_px},
                     {"sigma_px", std::isfinite(b.sigma_px) ? b.sigma_px : -1.0},
                     {"points", b.points},
                     {"used", b.used}});
    if (!b.used && b.points > 0)
      left_out += (left_out.empty() ? "" : ", ") + found[i]["view"].get<std::string>() + ":" +
                  found[i]["ball"].get<std::string>();
  }
  // The outlines left out, by view and ball (the library's note names them by index).
  const std::string note = left_out.empty() ? "" : "Left out (their own focal length disagrees): " + left_out;
  j.update({{"outlines", found},
            {"outline_focal_px", of.focal_px},
            {"outline_sigma_px", std::isfinite(of.sigma_px) ? of.sigma_px : -1.0},
            {"outline_rms_px", of.rms_px},
            {"birge_ratio", of.birge_ratio},
            {"outline_systematic_px", std::isfinite(of.systematic_px) ? of.systematic_px : -1.0},
            {"balls_used", of.balls_used},
            {"points", of.points},
            {"note", note}});
  if (!std::isfinite(of.sigma_px))
    return outlines_only ? unknown("the balls' outlines do not constrain it (" + of.note + ")")
                         : keep("the outlines do not constrain the focal length: " + of.note);
  if (outlines_only) {
    with_focal(lens, of.focal_px).write(s.out);
    j.update({{"refined", true},
              {"focal_px", of.focal_px},
              {"sigma_px", of.sigma_px},
              {"sigma_relative", of.sigma_px / of.focal_px},
              {"change_relative", of.focal_px / f0 - 1}});
    return j;
  }
  const double z = std::abs(of.focal_px - f0) / std::hypot(s0, of.sigma_px);
  j["disagreement_sigmas"] = z;
  if (z > 4)
    return keep("the outlines' focal length (" + std::to_string(of.focal_px) + " px) disagrees with the metadata's (" +
                std::to_string(f0) + " px) by " + std::to_string(z) + " combined sigmas; the metadata's is kept");
  const double w0 = 1 / (s0 * s0), wo = 1 / (of.sigma_px * of.sigma_px);
  const double f = (f0 * w0 + of.focal_px * wo) / (w0 + wo), sigma = 1 / std::sqrt(w0 + wo);
  with_focal(lens, f).write(s.out);
  j.update({{"refined", true},
            {"focal_px", f},
            {"sigma_px", sigma},
            {"sigma_relative", sigma / f},
            {"change_relative", f / f0 - 1}});
  return j;
}

}  // namespace rsibr
