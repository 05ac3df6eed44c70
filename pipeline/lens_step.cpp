#include "pipeline/lens_step.h"

#include "calib/lens/far_camera.h"
#include "calib/lens/outline_focal.h"

#include <cmath>

namespace rsibr {

nlohmann::json run_lens_step(const LensStep& s) {
  const LensModel lens = LensModel::read(s.calibrated);
  const double f0 = lens.intrinsics().at(0);
  nlohmann::json j = {{"source", s.source}, {"prior_focal_px", f0}, {"far_camera", false}};
  auto keep = [&](const std::string& why) {
    lens.write(s.out);
    j.update({{"refined", false}, {"why", why}, {"focal_px", f0}});
    return j;
  };
  // No focal length in the metadata: the outlines alone must give it, over a wide range.
  const bool outlines_only = s.source == "outlines";
  // Where the candidates are shown, for the errors that ask for --ball.
  auto candidates_hint = [&] {
    return s.pictures.empty()
               ? std::string("rsibr balls hdr/VIEW.exr --picture shows the candidates")
               : "the candidates are circled and numbered in " + s.pictures.filename().string() + "/VIEW.png";
  };
  auto unknown = [&](const std::string& why) -> nlohmann::json {
    throw std::invalid_argument("lens: the photos' metadata gives no focal length in pixels (" +
                                (s.metadata_note.empty() ? std::string("none found") : s.metadata_note) + ") and " +
                                why +
                                "; give the lens with --lens FILE (a .cameramodel, e.g. from rsibr calibrate), or "
                                "the ball with --ball VIEW:BALL=X,Y,R where it was not found (" +
                                candidates_hint() + ")");
  };
  const std::vector<ListedBall>& listed = s.balls.listed;
  if (s.source != "exif" && s.source != "lensfun" && !outlines_only) {
    for (const FoundView& v : s.balls.views)
      if (v.width != lens.width() || v.height != lens.height())
        throw std::invalid_argument("lens: view " + v.name + " is " + std::to_string(v.width) + "x" +
                                    std::to_string(v.height) + " but the lens (" + s.source + ") is " +
                                    std::to_string(lens.width()) + "x" + std::to_string(lens.height()));
    return keep("the lens was measured (" + s.source + ")");
  }

  // The listed balls of every view, located with the metadata's lens (a pinhole of the view's
  // diagonal where the view's size differs from it: crops); cut balls and points off their robust
  // cone are left out (calib/lens/outline_focal.h drops the rest).
  std::vector<std::vector<Vec2>> outlines;
  nlohmann::json found = nlohmann::json::array(), sizes_json = nlohmann::json::array();
  std::vector<std::pair<int, int>> sizes;
  bool same_size = true, crops = !s.balls.views.empty();
  std::string crop_note;
  for (const FoundView& v : s.balls.views) {
    const int w = v.width, h = v.height;
    sizes.push_back({w, h});
    const bool fits = w == lens.width() && h == lens.height();
    same_size = same_size && fits;
    // The view's evidence: its first listed chrome ball found, else its largest ball found.
    const int main = main_ball(v, listed);
    const BallCandidate* ball = main >= 0 ? &v.candidates[std::size_t(main)] : nullptr;
    const double radius = ball ? ball->loc.radius_px : -1.0;
    const bool fills = radius > 0 && fills_frame(radius, w, h);
    crops = crops && fills;
    sizes_json.push_back({{"view", v.name}, {"size", {w, h}}, {"ball_radius_px", radius}, {"fills_frame", fills}});
    if (ball) sizes_json.back()["ball_centre_px"] = {ball->loc.centre_px.x(), ball->loc.centre_px.y()};
    if (!fills && crop_note.empty())
      crop_note = v.name + (radius > 0 ? "'s ball does not fill its frame" : ": no ball found");
    if (!fits) continue;
    for (std::size_t b = 0; b < listed.size(); ++b) {
      const int pick = v.balls[b].candidate;
      if (pick < 0) continue;
      const BallCandidate& cand = v.candidates[std::size_t(pick)];
      if (cand.cut) continue;
      std::vector<Vec2> pts;
      for (std::size_t i = 0; i < cand.loc.outline_px.size() && i < cand.loc.fit.residual_px.size(); ++i)
        if (std::abs(cand.loc.fit.residual_px[i]) < 1.0) pts.push_back(cand.loc.outline_px[i]);
      outlines.push_back(pts);
      found.push_back({{"view", v.name},
                       {"ball", listed[b].name},
                       {"centre_px", {cand.loc.centre_px.x(), cand.loc.centre_px.y()}},
                       {"radius_px", cand.loc.radius_px}});
    }
  }
  j["views"] = sizes_json;
  if (crops) {
    // Crops of the ball (calib/lens/far_camera.h): the metadata's focal length is the uncropped frame's.
    const LensModel far = far_camera_lens(sizes);
    far.write(s.out);
    double alpha = 0;
    for (const auto& vj : sizes_json)
      alpha = std::max(alpha, std::asin(std::min(1.0, vj["ball_radius_px"].get<double>() / far.intrinsics().at(0))));
    j.update(
        {{"far_camera", true},
         {"refined", false},
         {"focal_px", far.intrinsics().at(0)},
         {"model", far.name()},
         {"canvas", {far.width(), far.height()}},
         {"ball_half_angle_deg", alpha / kDeg},
         {"why", "every view's ball fills its frame (diameter >= " + std::to_string(int(100 * kCropFillFraction)) +
                     "% of the shorter side): the photos are crops of the ball, so the far-camera model (a distant, "
                     "near-orthographic camera; the metadata's focal length belongs to the uncropped frame)"}});
    return j;
  }
  if (!same_size) {
    std::string list;
    for (std::size_t v = 0; v < sizes.size(); ++v)
      list += (v ? ", " : "") + s.balls.views[v].name + " " + std::to_string(sizes[v].first) + "x" +
              std::to_string(sizes[v].second);
    throw std::invalid_argument("lens: the views differ in size (" + list + ") but are not crops of the ball (" +
                                crop_note +
                                "); one lens serves views of one size: give each view's photos at the same size, or "
                                "the chrome ball with --ball VIEW:BALL=X,Y,R where it was not found (" +
                                candidates_hint() + ")");
  }
  if (!s.refine)
    return outlines_only ? unknown("--no-self-calibration keeps the balls from measuring it")
                         : keep("off (--no-self-calibration)");
  if (!outlines_only && !(s.prior_sigma_relative > 0)) return keep("the calibrate step states no uncertainty");
  const double s0 = outlines_only ? 0.0 : s.prior_sigma_relative * f0;
  if (!outlines_only) j["prior_sigma_px"] = s0;
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
