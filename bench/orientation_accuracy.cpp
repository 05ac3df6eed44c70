// Orientation accuracy of calib/orientation/view_orientation.h on rendered views: a chrome ball of a given
// radius in pixels in a real environment (cache/), views `spacing` degrees apart around it (20 by
// default), features on the cube faces or in the image (--domain), Gaussian noise
// of a given relative std dev; the ball found and every view oriented from the images alone (gauge:
// the true up of the first view), compared with the renderer's poses. One JSON line per run;
// bench/orientation_accuracy.py runs a grid and writes the docs/tradeoffs.md section.
#include "calib/orientation/view_orientation.h"

#include "calib_cases.h"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <chrono>
#include <iostream>

int main(int argc, char** argv) {
  using namespace rsibr;
  CLI::App app("Orientation accuracy on rendered views");
  double radius_px = 120, noise = 0.01, ball_prior_px = 0.25, radius_prior_px = 2, max_radius_fraction = 0.95,
         contrast = 0.01;
  int views = 4, max_features = 800;
  double spacing = 20;
  std::string domain = "cube";
  std::uint64_t seed = 5;
  bool refine = true, refine_tracks = true;
  int patch_half = 7;
  std::string env = std::string(RSIBR_CACHE_DIR) + "/assets/hdri/lobby.exr";
  app.add_option("--radius-px", radius_px, "Ball radius in pixels");
  app.add_option("--noise", noise, "Relative noise std dev");
  app.add_option("--views", views, "Views, --spacing degrees apart");
  app.add_option("--spacing", spacing, "Degrees between neighbouring views");
  app.add_option("--domain", domain, "Feature domain: cube or image")->check(CLI::IsMember({"cube", "image"}));
  app.add_option("--env", env, "Environment EXR");
  app.add_option("--seed", seed, "Noise seed");
  app.add_option("--refine", refine, "Refine ball centres jointly (1) or not (0)");
  app.add_option("--refine-tracks", refine_tracks, "Re-locate the tracks by patch alignment (1) or keep SIFT's (0)");
  app.add_option("--patch-half-size", patch_half, "Half size of the alignment patch, texels");
  app.add_option("--ball-prior-px", ball_prior_px, "Ball centre prior floor, pixels");
  app.add_option("--radius-prior-px", radius_prior_px, "Ball radius prior, pixels (0: held at the outline's)");
  app.add_option("--max-features", max_features, "SIFT features per view");
  app.add_option("--max-radius-fraction", max_radius_fraction,
                 "Features within this fraction of the ball's angular radius");
  app.add_option("--contrast-threshold", contrast, "SIFT contrast threshold");
  CLI11_PARSE(app, argc, argv);
  const double distance = 0.5, f = radius_px * distance / 0.05;
  const int w = int(radius_px * 2.5), h = int(radius_px * 2.3);
  SynthScene scene = testing::rig_scene(LensModel::pinhole(f, w, h), distance, false);
  scene.balls.resize(1);
  scene.environment.file = env;
  scene.environment.sanitize = true;
  scene.views.front().azimuths_deg.clear();
  for (int v = 0; v < views; ++v) scene.views.front().azimuths_deg.push_back(spacing * v);
  scene.views.front().roll_deg = 7;
  scene.views.front().look_at = scene.balls.front().centre;
  std::vector<ViewImage> images;
  std::vector<Mat3> truth;
  std::vector<Vec2> centre;
  std::vector<double> half_angle;
  std::vector<std::string> names;
  for (int v = 0; v < views; ++v) {
    const auto r = testing::render_view(scene, v, noise, seed + v);
    ViewImage vi;
    vi.radiance = r.radiance;
    images.push_back(vi);
    truth.push_back(r.pose.world_from_cam);
    centre.push_back(testing::ball_centre_px(r, 0));
    half_angle.push_back(std::asin(0.5 * scene.balls.front().diameter_m / testing::ball_centre_cam(r, 0).norm()));
    names.push_back("v" + std::to_string(v));
  }
  ViewOrientationOptions o;
  o.up = truth[0].transpose() * Vec3(0, 1, 0);
  o.refine_balls = refine;
  o.refine_tracks = refine_tracks;
  o.tracks.half_size = patch_half;
  o.ball_prior_px = ball_prior_px;
  o.ball_radius_prior_px = radius_prior_px;
  o.features.max_features = max_features;
  o.features.max_radius_fraction = max_radius_fraction;
  o.features.contrast_threshold = contrast;
  o.domain = domain == "image" ? FeatureDomain::image : FeatureDomain::cube;
  ViewOrientationReport rep;
  const auto t0 = std::chrono::steady_clock::now();
  PoseSet p;
  try {
    p = orient_views(names, images, scene.camera.lens, o, &rep);
  } catch (const std::exception& e) {  // e.g. a view sharing too few features: reported, not fatal
    std::cout << nlohmann::json({{"radius_px", radius_px},
                                 {"noise", noise},
                                 {"views", views},
                                 {"spacing", spacing},
                                 {"domain", domain},
                                 {"seed", seed},
                                 {"refine", refine},
                                 {"failed", e.what()}})
                     .dump()
              << "\n";
    return 0;
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const Mat3 g = p.views[0].world_from_cam * truth[0].transpose();
  nlohmann::json j = {{"radius_px", radius_px},
                      {"noise", noise},
                      {"views", views},
                      {"spacing", spacing},
                      {"domain", domain},
                      {"seed", seed},
                      {"refine", refine},
                      {"refine_tracks", refine_tracks},
                      {"tracks", rep.tracks},
                      {"rms_sigmas", rep.rms_sigmas},
                      {"relocated", rep.track_refinement.observations_refined},
                      {"dropped", rep.track_refinement.observations_dropped},
                      {"sigma_ratio", rep.track_refinement.median_sigma_ratio},
                      {"seconds", seconds}};
  for (int v = 1; v < views; ++v) {
    j["error_deg"].push_back(Eigen::AngleAxisd(p.views[v].world_from_cam.transpose() * g * truth[v]).angle() * 180 /
                             kPi);
    j["sigma_deg"].push_back(p.views[v].sigma_deg);
  }
  for (int v = 0; v < views; ++v) {
    j["centre_error_px"].push_back((rep.balls[v].centre_px - centre[v]).norm());
    // The half angle's error as pixels of image radius (f * d(tan a) = f / cos^2 a da).
    const double a = half_angle[v];
    j["radius_error_px"].push_back(f / (std::cos(a) * std::cos(a)) * (rep.balls[v].fit.cone.half_angle - a));
    j["features"].push_back(rep.features[v]);
  }
  std::cout << j.dump() << "\n";
  return 0;
}
