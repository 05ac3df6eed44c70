// rsibr balls: a merged view (rsibr hdr) -> the ball candidates calibration sees in it
// (calib/balls/ball_identification.h), numbered, with their measures and the ball each listed kind
// would take, and a picture of them circled and numbered (calib/balls/ball_candidates_picture.h). The
// tool for choosing --ball when a run cannot decide.
#include "cli/summary.h"
#include "cli/verbs.h"

#include "calib/balls/ball_candidates_picture.h"
#include "calib/balls/ball_identification.h"
#include "calib/view_image.h"
#include "formats/image_codecs.h"
#include "core/lens_model.h"
#include "formats/output_plan.h"
#include "core/srgb_curve.h"

#include <opencv2/imgproc.hpp>

#include <cctype>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <sstream>

namespace rsibr::cli {
namespace {

struct BallsArgs {
  std::string image, lens, picture, json, kinds = "chrome", at;
};

std::vector<ListedBall> parse_kinds(const std::string& text) {
  std::vector<ListedBall> out;
  std::stringstream in(text);
  std::string k;
  while (std::getline(in, k, ',')) {
    ListedBall b;
    if (k == "chrome")
      b.kind = BallKind::chrome;
    else if (k == "grey")
      b.kind = BallKind::grey;
    else if (k == "glossy")
      b.kind = BallKind::glossy;
    else
      throw std::invalid_argument("--kinds '" + text + "': expected a comma-separated list of chrome, grey, glossy");
    b.name = k + (out.empty() ? "" : std::to_string(out.size()));
    out.push_back(b);
  }
  if (out.empty()) throw std::invalid_argument("--kinds '" + text + "': no kind listed");
  return out;
}

int run_balls(const BallsArgs& a) {
  OutputPlan outputs({a.image, a.lens});
  const std::string picture = outputs.file(a.picture), json = outputs.file(a.json);
  const std::vector<ListedBall> listed = parse_kinds(a.kinds);
  ViewImage view;
  std::string ext = std::filesystem::path(a.image).extension().string();
  for (char& ch : ext) ch = char(std::tolower(static_cast<unsigned char>(ch)));
  if (ext == ".exr") {
    view = read_view_image(a.image);
  } else {
    // A photo: 8- or 16-bit, decoded with the sRGB curve (enough to see where the balls are).
    const cv::Mat bgr = read_image(a.image, cv::IMREAD_COLOR | cv::IMREAD_ANYDEPTH);
    if (bgr.empty()) throw std::invalid_argument(a.image + ": not an image this build can read");
    cv::Mat f;
    bgr.convertTo(f, CV_32FC3, bgr.depth() == CV_16U ? 1.0 / 65535 : 1.0 / 255);
    cv::cvtColor(f, f, cv::COLOR_BGR2RGB);
    f.forEach<cv::Vec3f>([](cv::Vec3f& p, const int*) {
      for (int k = 0; k < 3; ++k) p[k] = float(srgb_decode(p[k]));
    });
    view.radiance = f;
  }
  const int w = view.radiance.cols, h = view.radiance.rows;
  // Without a lens: a pinhole of the image's diagonal (a normal lens); where the balls are barely
  // depends on it.
  const LensModel lens =
      a.lens.empty() ? LensModel::pinhole(std::hypot(double(w), double(h)), w, h) : LensModel::read(a.lens);
  if (lens.width() != w || lens.height() != h)
    throw std::invalid_argument(a.image + ": " + std::to_string(w) + "x" + std::to_string(h) + " but the lens model " +
                                a.lens + " is " + std::to_string(lens.width()) + "x" + std::to_string(lens.height()));
  ViewCandidates vc;
  if (!a.at.empty()) {
    // One circle, located from the given guess and measured (what --ball would take).
    double x = 0, y = 0, r = 0;
    char c1 = 0, c2 = 0;
    std::istringstream in(a.at);
    if (!(in >> x >> c1 >> y >> c2 >> r) || c1 != ',' || c2 != ',' || !(in >> std::ws).eof() || !std::isfinite(x) ||
        !std::isfinite(y) || !(r > 1) || !std::isfinite(r))
      throw std::invalid_argument("--at '" + a.at + "': expected X,Y,R in pixels with R > 1");
    try {
      vc.cands.push_back(given_ball(view.radiance, lens, {Vec2(x, y), r}));
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument("--at '" + a.at + "': " + e.what());
    }
    vc.pick = assign_balls_in_view(vc.cands, listed);
  } else {
    vc = view_candidates(view.radiance, lens, listed);
  }
  nlohmann::json cands = nlohmann::json::array(), picks = nlohmann::json::array();
  std::cout << "#  centre_x centre_y radius  inliers support rms_px frame  texture rim  radial diffuse  looks like\n";
  for (std::size_t i = 0; i < vc.cands.size(); ++i) {
    const BallCandidate& c = vc.cands[i];
    std::string looks;
    for (BallKind k : {BallKind::chrome, BallKind::glossy, BallKind::grey})
      if (looks_like(c, k)) looks += std::string(looks.empty() ? "" : ",") + to_string(k);
    char line[256];
    std::snprintf(line, sizeof line, "%-2zu %8.1f %8.1f %7.1f %6.2f %7.2f %6.2f %6.2f %7.3f %5.2f %6.2f %7.3f  %s\n", i,
                  c.loc.centre_px.x(), c.loc.centre_px.y(), c.loc.radius_px, c.inlier_fraction, c.outline_support,
                  c.loc.fit.rms_px, c.frame_fraction, c.texture, c.rim_texture, c.rim_radial, c.diffuse_residual,
                  looks.empty() ? "-" : looks.c_str());
    std::cout << line;
    cands.push_back({{"index", i},
                     {"centre_px", {c.loc.centre_px.x(), c.loc.centre_px.y()}},
                     {"radius_px", c.loc.radius_px},
                     {"inlier_fraction", c.inlier_fraction},
                     {"outline_support", c.outline_support},
                     {"outline_rms_px", c.loc.fit.rms_px},
                     {"frame_fraction", c.frame_fraction},
                     {"texture", c.texture},
                     {"rim_texture", c.rim_texture},
                     {"rim_radial", c.rim_radial},
                     {"diffuse_residual", std::isfinite(c.diffuse_residual) ? c.diffuse_residual : -1.0},
                     {"looks_like", looks}});
  }
  for (std::size_t b = 0; b < listed.size(); ++b) {
    const int p = vc.pick[b];
    std::cout << to_string(listed[b].kind) << ": " << (p < 0 ? std::string("none") : "candidate " + std::to_string(p))
              << "\n";
    picks.push_back({{"kind", to_string(listed[b].kind)}, {"candidate", p}});
  }
  if (!picture.empty()) write_ball_candidates_picture(picture, view.radiance, vc);
  write_summary(json, {{"image", a.image}, {"width", w}, {"height", h}, {"candidates", cands}, {"picks", picks}});
  outputs.commit();
  return 0;
}

}  // namespace

Runner add_balls(CLI::App& app) {
  auto a = std::make_shared<BallsArgs>();
  CLI::App* c = app.add_subcommand("balls", "List the ball candidates in a merged view, numbered, with a picture");
  c->footer(
      "Every circle the ball finder located in the image (a Hough transform, a frame-filling guess for photos cropped "
      "to the ball, each located by a cone fit to its outline), numbered, with its outline quality and appearance, "
      "and the candidate each listed kind would take. Copy a candidate's centre and radius into rsibr process "
      "--ball VIEW:BALL=X,Y,R when a run cannot decide.\n"
      "Example: rsibr balls run/hdr/view1.exr --picture candidates.png");
  c->add_option("image", a->image, "Merged view EXR (rsibr hdr), any float RGB EXR, or a photo (decoded as sRGB)")
      ->required();
  c->add_option("--lens", a->lens, "mrcal .cameramodel (default: a pinhole of the image's diagonal)");
  c->add_option("--kinds", a->kinds, "The balls to assign, comma-separated: chrome, grey, glossy (default chrome)");
  c->add_option("--at", a->at, "Locate and measure one ball at X,Y,R (pixels) instead of searching");
  c->add_option("--picture", a->picture, "Write the candidates circled and numbered to this PNG");
  c->add_option("--json", a->json, "Write a JSON summary to FILE ('-' for stdout)");
  return [a] { return run_balls(*a); };
}

}  // namespace rsibr::cli
