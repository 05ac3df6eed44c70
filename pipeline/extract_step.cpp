#include "pipeline/extract_step.h"

#include "calib/extraction/lambert_consensus.h"
#include "calib/extraction/occluded_light.h"
#include "calib/extraction/occluders.h"
#include "calib/probe/probe.h"
#include "calib/extraction/sphere_map_extraction.h"
#include "formats/image_codecs.h"
#include "core/preview_exposure.h"
#include "core/progress.h"
#include "lights/recovered_probe.h"
#include "pipeline/default_sizes.h"
#include "pipeline/mask_picture.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <stdexcept>

namespace rsibr {

namespace {

nlohmann::json finding_json(const std::string& ball, const BallFinding& f) {
  nlohmann::json j = {{"ball", ball}, {"status", f.status}, {"note", f.note}};
  if (f.predicted_px) j["predicted_px"] = {f.predicted_px->x(), f.predicted_px->y(), f.predicted_radius_px};
  if (f.disagreement >= 0) j["disagreement_radii"] = f.disagreement;
  if (!f.ball) return j;
  const BallCandidate& b = *f.ball;
  j.update({{"centre_px", {b.loc.centre_px.x(), b.loc.centre_px.y()}},
            {"radius_px", b.loc.radius_px},
            {"outline_rms_px", b.loc.fit.rms_px},
            {"inlier_fraction", b.inlier_fraction},
            {"texture", b.texture},
            {"mirror_score", b.mirror_score},
            {"rim_radial", b.rim_radial},
            {"diffuse_residual", std::isfinite(b.diffuse_residual) ? b.diffuse_residual : -1.0},
            {"frame_fraction", b.frame_fraction},
            {"cut", b.cut}});
  return j;
}

}  // namespace

ExtractedMaps run_extract_step(const ExtractStep& s) {
  if (!s.lens) throw std::invalid_argument("extract: no lens");
  if (!s.read_view) throw std::invalid_argument("extract: no reader of the merged views");
  ExtractedMaps out;
  const LensModel& lens = *s.lens;
  const PoseSet& poses = s.poses;
  const std::vector<ListedBall>& listed = s.found.listed;
  // World down for the stands and the photographer: -Y when the world is +Y up, else the first camera's +y.
  const Vec3 world_down = poses.gauge != "first-view" ? Vec3(0, -1, 0) : Vec3(0, 1, 0);
  int chrome_index = -1;
  for (std::size_t b = 0; b < listed.size(); ++b)
    if (listed[b].kind == BallKind::chrome && chrome_index < 0) chrome_index = int(b);
  const double chrome_radius_m = chrome_index >= 0 && listed[std::size_t(chrome_index)].diameter_m
                                     ? 0.5 * *listed[std::size_t(chrome_index)].diameter_m
                                     : 0.05;
  // Pass 1: every view's candidates and its chrome ball (the anchor).
  std::vector<ViewBalls> vb;
  std::vector<std::size_t> used;           // view indices
  std::vector<ViewCandidates> used_found;  // their candidates through the lens, and the balls step's picks
  std::vector<const FoundView*> used_view;
  nlohmann::json views = nlohmann::json::array();
  Progress bar("extract", s.progress);
  const double steps = 2.0 * double(s.views.size());
  for (std::size_t vi = 0; vi < s.views.size(); ++vi) {
    const std::string& name = s.views[vi];
    const ViewPose* pose = poses.find(name);
    if (!pose) {
      views.push_back({{"name", name},
                       {"left_out", "no pose (the orient step found no chrome ball in it)"},
                       {"balls", nlohmann::json::array()}});
      continue;
    }
    const FoundView* fv = s.found.find(name);
    if (!fv) throw std::invalid_argument("extract: the balls step found no view '" + name + "' (rerun it)");
    ViewCandidates vc = candidates_for_lens(*fv, lens);
    ViewBalls one;
    one.name = name;
    one.world_from_cam = pose->world_from_cam;
    one.candidates = vc.cands;
    if (chrome_index >= 0) {
      const int k = vc.pick[std::size_t(chrome_index)];
      if (fv->balls[std::size_t(chrome_index)].status == "given") {
        one.chrome = vc.cands[std::size_t(k)].loc.fit.cone;
      } else if (pose->ball) {
        one.chrome = pose->ball;  // refined with the orientations (the outline lies inside its limb)
      } else if (k >= 0) {
        one.chrome = vc.cands[std::size_t(k)].loc.fit.cone;
      }
    }
    vb.push_back(std::move(one));
    used.push_back(vi);
    used_found.push_back(std::move(vc));
    used_view.push_back(fv);
    bar.update(double(vi + 1) / steps);
  }
  const std::vector<RigMember> rig = fit_ball_rig(vb, listed);
  for (ViewBalls& v : vb)
    if (auto a = anchor_from_rig(v, rig, listed)) {
      v.chrome = a->chrome;
      v.anchor_note = "chrome ball placed by the rig from ball " + a->placed_from + " (within " +
                      std::to_string(a->disagreement).substr(0, 4) + " chrome radii)";
    }
  int anchored = 0;
  for (const ViewBalls& v : vb) anchored += v.chrome.has_value();
  const bool trust_views = anchored < 2;  // one view: nothing to check it against
  // Map sizes (pipeline/default_sizes.h): from the chrome ball's largest pixel radius over the
  // views, scaled by the rig's radius ratio for the other balls (they are decided view by view
  // below, after the size is needed); a size the user gives wins.
  double chrome_px = 0;
  for (const ViewBalls& v : vb)
    if (v.chrome) chrome_px = std::max(chrome_px, ball_pixel_radius(*v.chrome, lens));
  std::vector<int> map_size(listed.size(), s.map_size);
  for (std::size_t b = 0; b < listed.size(); ++b)
    if (s.map_size <= 0) {
      const double scale = rig.size() == listed.size() && rig[b].known && rig[b].scale > 0 ? rig[b].scale : 1.0;
      map_size[b] = default_map_size(listed[b].kind, chrome_px * scale);
    }
  const int probe_width = s.probe_width > 0
                              ? s.probe_width
                              : default_probe_width(chrome_index >= 0 ? map_size[std::size_t(chrome_index)] : 64);
  // Pass 2: each view's balls decided, extracted; the chrome maps masked.
  std::vector<MapSet> sets(listed.size());
  std::vector<double> view_disagreement(vb.size(), -1.0);  // per view: its other balls' largest
  // Per grey map: what occludes its light (calib/extraction/occluded_light.h), restored once the probe is known.
  struct GreyScene {
    std::size_t ball;
    std::string view;
    BallCone cone;
    Mat3 world_from_cam;
    std::vector<OccluderLight> occluders;
    Vec3 chrome_centre = Vec3::Zero();  // camera frame, the grey ball's radii
  };
  std::vector<GreyScene> grey_scenes;
  std::map<std::string, cv::Mat> chrome_hidden;  // per view: the chrome texels another ball hides
  for (std::size_t k = 0; k < vb.size(); ++k) {
    const std::size_t vi = used[k];
    const std::string& name = s.views[vi];
    const ViewImage img = s.read_view(name);
    std::vector<BallFinding> found = identify_view_balls(vb[k], rig, listed, img.radiance, lens, {}, {}, trust_views);
    for (std::size_t b = 0; b < listed.size(); ++b)
      if (int(b) != chrome_index && found[b].found() && found[b].disagreement > 0)
        view_disagreement[k] = std::max(view_disagreement[k], found[b].disagreement);
    for (std::size_t b = 0; b < listed.size(); ++b)
      if (used_view[k]->balls[b].status == "given") {
        found[b] = BallFinding{};
        found[b].status = "given";
        found[b].note = "--ball";
        found[b].ball = used_found[k].cands[std::size_t(used_found[k].pick[b])];
        if (int(b) == chrome_index && vb[k].chrome) found[b].ball->loc.fit.cone = *vb[k].chrome;
      }
    const Mat3 world_from_cam = vb[k].world_from_cam;
    const Vec3 down_cam = world_from_cam.transpose() * world_down;
    std::vector<OtherBall> others;
    for (std::size_t b = 0; b < listed.size(); ++b)
      if (int(b) != chrome_index && found[b].found() && chrome_index >= 0 && found[std::size_t(chrome_index)].found()) {
        const BallCone chrome = found[std::size_t(chrome_index)].ball->loc.fit.cone, cone = found[b].ball->loc.fit.cone;
        // The radius over the chrome's: the rig's, else the listed diameters', else the same distance as the chrome ball.
        double scale = rig.size() == listed.size() && rig[b].known ? rig[b].scale : 0;
        if (!(scale > 0) && listed[b].diameter_m && listed[std::size_t(chrome_index)].diameter_m)
          scale = *listed[b].diameter_m / *listed[std::size_t(chrome_index)].diameter_m;
        if (!(scale > 0)) scale = std::sin(cone.half_angle) / std::sin(chrome.half_angle);
        others.push_back({listed[b].name, cone, scale});
      }
    nlohmann::json vj = {{"name", name}, {"balls", nlohmann::json::array()}};
    for (std::size_t b = 0; b < listed.size(); ++b) {
      const ListedBall& ball = listed[b];
      nlohmann::json bj = finding_json(ball.name, found[b]);
      if (!found[b].found()) {
        vj["balls"].push_back(bj);
        continue;
      }
      const BallCone cone = found[b].ball->loc.fit.cone;
      ExtractOptions eo;
      eo.size = map_size[b];
      eo.mirror = ball.kind == BallKind::chrome;
      eo.indexing = eo.mirror ? SphereIndexing::reflection : SphereIndexing::orthographic;
      eo.camera_mask_deg = eo.mirror ? 12.0 : 0.0;
      eo.down = down_cam;
      eo.material = eo.mirror ? "{type: mirror}" : "{type: lambert}";
      // Radii of this ball over the chrome's (the extraction's geometry is in this ball's radii).
      double own_scale = 1;
      for (const OtherBall& o : others)
        if (o.name == ball.name) own_scale = o.scale;
      std::vector<OtherBall> rest;
      if (chrome_index >= 0 && int(b) != chrome_index && found[std::size_t(chrome_index)].found())
        rest.push_back(
            {listed[std::size_t(chrome_index)].name, found[std::size_t(chrome_index)].ball->loc.fit.cone, 1.0});
      for (const OtherBall& o : others)
        if (o.name != ball.name) rest.push_back(o);
      for (const OtherBall& o : rest) {
        Occluder f;
        f.centre = o.scale / own_scale * o.cone.axis.normalized() / std::sin(o.cone.half_angle);
        f.radius = 1.03 * o.scale / own_scale;
        f.what = "ball " + o.name + " in front";
        eo.in_front.push_back(f);
      }
      if (eo.mirror && int(b) == chrome_index) eo.occluders = chrome_occluders(cone, rest, down_cam, chrome_radius_m);
      if (ball.kind == BallKind::grey && s.occluder_light && chrome_index >= 0 &&
          found[std::size_t(chrome_index)].found()) {
        // The photographer, in this ball's radii, lit as the view's chrome ball sees it. The other
        // balls are not restored: restoring the chrome ball beside the grey one did not lower the
        // error on the held-out shoots (docs/tradeoffs.md, "calib/extraction/occluded_light.h: what is restored").
        GreyScene g{b, name, cone, world_from_cam, {}, Vec3::Zero()};
        for (const OtherBall& o : rest)
          if (o.name == listed[std::size_t(chrome_index)].name)
            g.chrome_centre = o.scale / own_scale * o.cone.axis.normalized() / std::sin(o.cone.half_angle);
        for (const Occluder& o : chrome_occluders(cone, {}, down_cam, chrome_radius_m * own_scale))
          if (o.what == "photographer") g.occluders.push_back({o, OccluderLight::seen_by_chrome, 0});
        grey_scenes.push_back(std::move(g));
      }
      cv::Mat hidden;
      MapView mv = extract_sphere_map(img.radiance, img.flags, lens, cone, world_from_cam, eo,
                                      s.occluder_light && int(b) == chrome_index ? &hidden : nullptr);
      if (s.occluder_light && int(b) == chrome_index) chrome_hidden[name] = hidden;
      mv.image = name;
      mv.attributes["ball"] = ball.name;
      mv.attributes["ballKind"] = to_string(ball.kind);
      mv.attributes["frame"] = "world (poses.yaml)";
      mv.attributes["identified"] = found[b].status;
      const cv::Mat& conf = mv.confidence;
      bj["confident_fraction"] = cv::countNonZero(conf > 0.5) / (kPi / 4 * eo.size * eo.size);
      nlohmann::json occ = nlohmann::json::array();
      for (const Occluder& o : eo.occluders) occ.push_back(o.what);
      for (const Occluder& o : eo.in_front) occ.push_back(o.what);
      bj["masked"] = occ;
      vj["balls"].push_back(bj);
      sets[b].views.push_back(std::move(mv));
    }
    views.push_back(vj);
    bar.update(double(vb.size() + k + 1) / steps);
  }
  bar.done();
  auto ball_entry = [&](const std::string& view, const std::string& ball) -> nlohmann::json* {
    for (auto& vj : views)
      if (vj["name"] == view)
        for (auto& bj : vj["balls"])
          if (bj["ball"] == ball) return &bj;
    return nullptr;
  };
  // A view whose other balls disagree with the rig has its chrome ball or its rotation off
  // (calib/balls/ball_identification.h, rig_suspects): its chrome map stays out of the probe.
  const RigSuspects suspects = rig_suspects(view_disagreement);
  std::vector<MapView> chrome_left_out;  // still the view's own light for its grey ball (below)
  if (chrome_index >= 0 && std::count(suspects.suspect.begin(), suspects.suspect.end(), 1) > 0) {
    std::vector<MapView> kept;
    for (MapView& mv : sets[std::size_t(chrome_index)].views) {
      const std::size_t k = std::size_t(
          std::find_if(vb.begin(), vb.end(), [&](const ViewBalls& x) { return x.name == mv.image; }) - vb.begin());
      if (k < vb.size() && suspects.suspect[k]) {
        if (nlohmann::json* bj = ball_entry(vb[k].name, listed[std::size_t(chrome_index)].name)) {
          char note[200];
          std::snprintf(note, sizeof note,
                        "left out of the probe: the view's other balls lie %.2f chrome radii from where the rig "
                        "puts them (median of the views %.2f): its chrome ball or its rotation is off",
                        view_disagreement[k], suspects.median);
          (*bj)["status"] = "left out: disagrees with the rig";
          (*bj)["note"] = note;
        }
        chrome_left_out.push_back(std::move(mv));
        continue;
      }
      kept.push_back(std::move(mv));
    }
    sets[std::size_t(chrome_index)].views = std::move(kept);
  }
  // Grey balls: the light the photographer takes from them restored, from the chrome maps' probe
  // and each view's own chrome map (calib/extraction/occluded_light.h). The probe is the one the sources step
  // makes (the light clipped in every view recovered from the grey balls, lights/recovered_probe.h):
  // the restored share is the photographer's light over the whole light, so a probe that lacks a
  // clipped sun overstates it (by 2-3x on shoots where the sun is 60% of the light).
  if (!grey_scenes.empty() && !sets[std::size_t(chrome_index)].views.empty()) {
    const auto fresnel = chrome_fresnel_from_spec(s.chrome_fresnel, "--chrome-fresnel");
    ProbeOptions po;
    po.width = probe_width;
    po.fresnel = fresnel.get();
    std::vector<GreyBallMaps> grey_maps;
    for (std::size_t b = 0; b < listed.size(); ++b)
      if (listed[b].kind == BallKind::grey && !sets[b].views.empty())
        grey_maps.push_back({listed[b].name, &sets[b], Vec3::Constant(s.grey_albedo)});
    SourceRecoveryOptions ro;
    ro.seed = s.seed;
    // Only the light is needed here, not its sigma, and the regions' centroids serve a 64 x 32
    // quadrature (refining them cost 12 s of a 26 s extract on a shoot with 8 sources, and the
    // grey maps came out no closer to the truth).
    ro.jackknife = false;
    ro.refine = false;
    const RecoveredProbe probe =
        recover_probe_sources(sets[std::size_t(chrome_index)], po, grey_maps, {}, ro, s.recover_sources);
    // Clipped texels count as seen: the recovery put its light there (0 where it put none). Left
    // unseen, a sun's quadrature cell, mostly clipped glare, dropped out of both irradiances
    // (on the clipped-sun test's low sun, view00's grey map went from 0.33 to 0.10 stops).
    cv::Mat seen_weight = probe.measured.weight.clone();
    for (int y = 0; y < seen_weight.rows; ++y)
      for (int x = 0; x < seen_weight.cols; ++x)
        if (probe.measured.clipped.at<float>(y, x) > 0)
          seen_weight.at<float>(y, x) = std::max(seen_weight.at<float>(y, x), 1.0f);
    const OpenLight light = open_light(probe.env, seen_weight, fresnel.get(), std::min(64, probe_width));
    for (const GreyScene& g : grey_scenes) {
      auto of_view = [&](std::vector<MapView>& maps) -> MapView* {
        for (MapView& mv : maps)
          if (mv.image == g.view) return &mv;
        return nullptr;
      };
      MapView* grey = of_view(sets[g.ball].views);
      if (!grey) continue;
      // A view left out of the probe keeps its own chrome map here: the photographer's light is
      // read in the view's frame, whatever its rotation's error.
      const MapView* chrome = of_view(sets[std::size_t(chrome_index)].views);
      if (!chrome) chrome = of_view(chrome_left_out);
      const OccludedLight ol = occluded_light(*grey, g.world_from_cam, g.cone, g.occluders, light, chrome,
                                              g.chrome_centre, chrome_hidden[g.view]);
      restore_occluded_light(*grey, ol);
      char text[160];
      std::snprintf(text, sizeof text, "restored: mean %.3f, largest %.3f stops%s", ol.mean_stops, ol.max_stops,
                    chrome ? "" : " (none: the view has no chrome map)");
      grey->attributes["occluderLight"] = text;
      if (nlohmann::json* bj = ball_entry(g.view, listed[g.ball].name))
        (*bj)["occluder_light"] = {
            {"mean_stops", ol.mean_stops}, {"largest_stops", ol.max_stops}, {"photographer", chrome != nullptr}};
    }
  }
  // Grey balls: what one view alone sees differently (the photographer's shadow) is masked, a view
  // mostly so is left out (calib/extraction/lambert_consensus.h).
  for (std::size_t b = 0; b < listed.size(); ++b) {
    if (listed[b].kind != BallKind::grey) continue;
    const std::vector<LambertConsensusView> cons = mask_lambert_inconsistencies(sets[b].views);
    std::vector<MapView> kept;
    for (std::size_t k = 0; k < cons.size(); ++k) {
      MapView& mv = sets[b].views[k];
      nlohmann::json* bj = ball_entry(mv.image, listed[b].name);
      if (bj) {
        (*bj)["consensus"] = {
            {"judged", cons[k].judged}, {"masked", cons[k].masked}, {"median_stops", cons[k].median_stops}};
        (*bj)["confident_fraction"] = cv::countNonZero(mv.confidence > 0.5) / (kPi / 4 * mv.rgb.cols * mv.rgb.rows);
      }
      if (cons[k].left_out) {
        if (bj) {
          (*bj)["status"] = "left out: inconsistent with the other views";
          (*bj)["note"] = std::to_string(cons[k].masked) + " of " + std::to_string(cons[k].judged) +
                          " texels differ from the other views' median by more than 0.12 stops (median " +
                          std::to_string(cons[k].median_stops).substr(0, 5) +
                          "): a shadow or occluder of this view alone";
        }
        continue;
      }
      kept.push_back(std::move(mv));
    }
    sets[b].views = std::move(kept);
  }
  // Each map's mask for the report.
  for (std::size_t b = 0; b < listed.size(); ++b)
    for (const MapView& mv : sets[b].views) {
      const std::string image = mv.image;
      const std::string name = int(b) == chrome_index ? image + ".png" : image + "-" + listed[b].name + ".png";
      out.masks[name] = png_bytes(mask_picture(mv, preview_exposure(mv.rgb)), name);
      if (nlohmann::json* bj = ball_entry(image, listed[b].name)) (*bj)["mask"] = "masks/" + name;
    }
  for (std::size_t b = 0; b < listed.size(); ++b)
    if (sets[b].views.empty())
      throw std::runtime_error("ball '" + listed[b].name +
                               "' was found in no view (see the balls' notes with --json; "
                               "give it with --ball VIEW:" +
                               listed[b].name + "=X,Y,R)");
  nlohmann::json rj = nlohmann::json::array();
  for (std::size_t b = 0; b < listed.size(); ++b) {
    const RigMember& m = rig.size() == listed.size() ? rig[b] : RigMember{};
    rj.push_back({{"ball", listed[b].name},
                  {"known", m.known},
                  {"offset_chrome_radii", {m.offset.x(), m.offset.y(), m.offset.z()}},
                  {"scale", m.scale},
                  {"scale_from_diameters", m.scale_given},
                  {"views_agreeing", m.support},
                  {"rms_radii", m.rms}});
  }
  nlohmann::json sizes = nlohmann::json::object();
  std::size_t bytes = 0;
  for (std::size_t b = 0; b < listed.size(); ++b) {
    sizes[listed[b].name] = map_size[b];
    bytes += map_set_bytes(map_size[b], sets[b].views.size());
  }
  out.summary = {
      {"views", views},
      {"map_size", sizes},
      {"map_size_source",
       s.map_size > 0 ? "--map-size"
                      : "the balls' pixel radii (chrome: " + std::to_string(int(std::lround(chrome_px))) + " px)"},
      {"probe_width", probe_width},
      {"probe_width_source", s.probe_width > 0 ? "--probe-width" : "the chrome map's size"},
      {"maps_memory_mb", double(bytes) / (1 << 20)},
      {"rig", rj},
      {"chrome_radius_m", chrome_radius_m},
      {"chrome_radius_source",
       chrome_index >= 0 && listed[std::size_t(chrome_index)].diameter_m ? "listed diameter" : "assumed 5 cm"}};
  out.sets = std::move(sets);
  return out;
}

}  // namespace rsibr
