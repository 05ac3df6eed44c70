#include "export/blender_scene.h"

#include "bake/brdf_spec.h"
#include "calib/balls/ball_offset.h"
#include "calib/balls/balls_file.h"
#include "calib/lens/far_camera.h"
#include "calib/orientation/pose_file.h"
#include "calib/view_image.h"
#include "core/cell_centred_latlong.h"
#include "formats/exr_file.h"
#include "formats/exr_io.h"
#include "core/lens_model.h"
#include "formats/map_set.h"
#include "export/blender_axes.h"
#include "pipeline/step_record.h"

#include <opencv2/imgproc.hpp>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <fstream>
#include <iterator>
#include <stdexcept>

namespace rsibr {
namespace detail {
extern const char* const embedded_blender_script;
}

namespace {

namespace fs = std::filesystem;

// A step's record (pipeline/step_record.h): a missing or malformed one is the input's problem.
StepRecord record_of(const fs::path& run, const std::string& step) {
  try {
    return read_step_record(run, step);
  } catch (const std::runtime_error& e) {
    throw std::invalid_argument(e.what());
  }
}

const nlohmann::json& field(const nlohmann::json& j, const std::string& key, const fs::path& file) {
  if (!j.is_object() || !j.contains(key)) throw std::invalid_argument(file.string() + ": no '" + key + "'");
  return j.at(key);
}

fs::path existing(const fs::path& file) {
  if (!fs::is_regular_file(file))
    throw std::invalid_argument(file.string() + ": missing (has the run reached this step?)");
  return file;
}

// EXR bytes through a temporary file (the EXR writer writes files).
std::vector<unsigned char> exr_bytes(const std::vector<ExrPartOut>& parts) {
  const fs::path tmp = fs::temp_directory_path() / ("rsibr-export-" + std::to_string(::getpid()) + ".exr");
  try {
    write_exr(tmp.string(), parts);
    std::ifstream in(tmp, std::ios::binary);
    std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    fs::remove(tmp);
    return bytes;
  } catch (...) {
    std::error_code ec;
    fs::remove(tmp, ec);
    throw;
  }
}

std::vector<unsigned char> rgb_exr_bytes(const cv::Mat& rgb) {
  ExrPartOut part;
  part.channels = {{"R", rgb, 0}, {"G", rgb, 1}, {"B", rgb, 2}};
  return exr_bytes({part});
}

// The merged view resampled onto the pinhole with the lens's core intrinsics: Blender's camera
// has no distortion. A pinhole lens's view is returned as it is.
cv::Mat undistorted(const cv::Mat& radiance, const LensModel& lens) {
  if (lens.name() == "LENSMODEL_PINHOLE") return radiance;
  const std::vector<double>& in = lens.intrinsics();
  const double fx = in[0], fy = in[1], cx = in[2], cy = in[3];
  cv::Mat map_x(radiance.size(), CV_32FC1), map_y(radiance.size(), CV_32FC1);
  for (int y = 0; y < radiance.rows; ++y)
    for (int x = 0; x < radiance.cols; ++x) {
      const Vec2 p = lens.project(Vec3((x - cx) / fx, (y - cy) / fy, 1.0));
      map_x.at<float>(y, x) = float(p.x());
      map_y.at<float>(y, x) = float(p.y());
    }
  cv::Mat out;
  cv::remap(radiance, out, map_x, map_y, cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar::all(0));
  return out;
}

// The Lambert albedo of a computed map set's material (rsibr process bakes Lambert greys).
Vec3 lambert_albedo(const MapSet& set, const fs::path& file) {
  if (set.views.empty()) throw std::invalid_argument(file.string() + ": no views");
  const YAML::Node spec = YAML::Load(set.views[0].material);
  if (!spec.IsMap() || !spec["type"] || spec["type"].as<std::string>() != "lambert" || !spec["albedo"])
    throw std::invalid_argument(file.string() + ": material '" + set.views[0].material +
                                "' is not Lambert (the only grey material exported)");
  const YAML::Node a = spec["albedo"];
  if (a.IsSequence() && a.size() == 3) return Vec3(a[0].as<double>(), a[1].as<double>(), a[2].as<double>());
  return Vec3::Constant(a.as<double>());
}

// The views where the extract step found ball `name`: its circle as a cone (axis through the
// circle's centre, half angle from the rays through its rim) beside the pose's chrome cone.
std::vector<BallOffsetView> ball_views(const nlohmann::json& summary, const PoseSet& poses, const LensModel& lens,
                                       const std::string& name) {
  std::vector<BallOffsetView> views;
  for (const auto& view : summary.value("views", nlohmann::json::array())) {
    const ViewPose* pose = poses.find(view.value("name", ""));
    if (!pose || !pose->ball) continue;
    for (const auto& found : view.value("balls", nlohmann::json::array())) {
      if (found.value("ball", "") != name || found.value("status", "") != "found" || !found.contains("centre_px") ||
          !found.contains("radius_px"))
        continue;
      const Vec2 c(found["centre_px"][0], found["centre_px"][1]);
      const double r = found["radius_px"];
      BallCone cone;
      cone.axis = lens.unproject(c).normalized();
      double half = 0;
      for (const Vec2& d : {Vec2(r, 0), Vec2(0, r)})
        half += 0.25 * angle_between(lens.unproject(c + d), lens.unproject(c - d));
      cone.half_angle = half;
      if (cone.half_angle > 0 && cone.half_angle < 0.5 * kPi)
        views.push_back({pose->world_from_cam, *pose->ball, cone});
    }
  }
  return views;
}

// The camera's distance from the chrome centre along its chrome cone. The cone's half angle gives
// it to about 1% (a fraction of a pixel on the outline's radius), which moves a ball 30 cm away by
// pixels; the directions in which the view sees the other placed balls give it far better. The
// distance minimises ((d - d0) / (d0 cot alpha))^2 + sum_b angle_b(d)^2 (one angular error for
// outline radii and centres): golden-section search over [0.8, 1.25] d0.
double camera_distance(const ViewPose& v, double d0, const Vec3& chrome_centre_world,
                       const std::vector<std::pair<Vec3, Vec3>>& seen) {  // (ball centre, camera-frame ray)
  if (seen.empty()) return d0;
  const double prior = d0 / std::tan(v.ball->half_angle);
  auto cost = [&](double d) {
    const Vec3 camera = chrome_centre_world - v.world_from_cam * (v.ball->axis * d);
    double e = (d - d0) * (d - d0) / (prior * prior);
    for (const auto& [centre, ray] : seen) {
      const Vec3 in_cam = (v.world_from_cam.transpose() * (centre - camera)).normalized();
      const double a = std::atan2(in_cam.cross(ray).norm(), in_cam.dot(ray));
      e += a * a;
    }
    return e;
  };
  const double phi = 0.5 * (std::sqrt(5.0) - 1);
  double lo = 0.8 * d0, hi = 1.25 * d0;
  for (int i = 0; i < 80; ++i) {
    const double a = hi - phi * (hi - lo), b = lo + phi * (hi - lo);
    if (cost(a) < cost(b))
      hi = b;
    else
      lo = a;
  }
  return 0.5 * (lo + hi);
}

// The world image: `env` in Blender's cell-centred convention, `width` wide (0: twice env's, at
// most 8192), as EXR bytes.
std::vector<unsigned char> world_exr(const EnvMap& env, int width) {
  if (width <= 0) width = std::min(8192, 2 * env.layout.width());
  const EnvMap world = to_cell_centred_latlong(env, width, std::max(1, width / 2));
  ExrPartOut part;
  part.channels = {{"R", world.pixels, 0}, {"G", world.pixels, 1}, {"B", world.pixels, 2}};
  return exr_bytes({part});
}

std::vector<unsigned char> fresnel_exr(const std::string& spec) {
  const std::vector<Vec3> table = fresnel_table(spec);
  cv::Mat rgb(1, int(table.size()), CV_32FC3);
  for (int k = 0; k < rgb.cols; ++k)
    rgb.at<cv::Vec3f>(0, k) = cv::Vec3f(float(table[k].x()), float(table[k].y()), float(table[k].z()));
  return rgb_exr_bytes(rgb);
}

}  // namespace

const char* blender_scene_script() { return detail::embedded_blender_script; }

std::vector<Vec3> fresnel_table(const std::string& fresnel_spec, int n) {
  const auto fresnel = make_fresnel(YAML::Load(fresnel_spec));
  std::vector<Vec3> table(std::size_t(std::max(n, 1)));
  for (int k = 0; k < int(table.size()); ++k) table[std::size_t(k)] = fresnel->eval((k + 0.5) / table.size());
  return table;
}

namespace {

// `json_file` is set to each record before its fields are read, so a record of the wrong shape is
// named in the error.
BlenderExport export_from_run(const fs::path& run, const BlenderExportOptions& options, fs::path& json_file) {
  BlenderExport out;
  out.samples = options.samples;
  const fs::path extract_file = run / "steps" / "extract.json";
  json_file = extract_file;
  const StepRecord extract = record_of(run, "extract");
  const nlohmann::json& summary = extract.summary;
  const double chrome_radius = field(summary, "chrome_radius_m", extract_file).get<double>();

  const LensModel lens = LensModel::read(existing(run / "lens.cameramodel"));
  if (lens.intrinsics().size() < 4)
    throw std::invalid_argument((run / "lens.cameramodel").string() + ": " + lens.name() +
                                " has no pinhole core (fx, fy, cx, cy) for Blender's camera");
  const PoseSet poses = read_pose_file(existing(run / "poses.yaml").string());

  // The balls: names and kinds as the balls step listed them (DIR/balls.json), places from the
  // extract step's rig; a ball the views saw is placed from their circles by calib/balls/ball_offset.h
  // (the rig's offset is their mean, which carries each view's weak depth).
  const nlohmann::json& rig = field(summary, "rig", extract_file);
  const std::vector<ListedBall> listed = read_balls_file(existing(run / "balls.json")).listed;
  Vec3 chrome_centre = Vec3::Zero();
  bool have_chrome = false;
  for (std::size_t b = 0; b < listed.size(); ++b) {
    const std::string name = listed[b].name, kind = to_string(listed[b].kind);
    const nlohmann::json* member = nullptr;
    for (const auto& m : rig)
      if (m.at("ball").get<std::string>() == name) member = &m;
    if (!member || !member->at("known").get<bool>()) {
      out.notes.push_back("ball '" + name + "' is left out: too few views agree on its place (the rig)");
      continue;
    }
    BlenderBall ball;
    ball.name = name;
    ball.kind = kind;
    const auto& o = member->at("offset_chrome_radii");
    const double scale = member->at("scale").get<double>();
    Vec3 offset(o[0], o[1], o[2]);
    if (kind != "chrome")
      if (const auto weighted = weighted_ball_offset(ball_views(summary, poses, lens, name), scale)) offset = *weighted;
    ball.centre = blender_from_rsibr() * offset * chrome_radius;
    ball.radius = scale * chrome_radius;
    if (kind == "chrome") {
      const fs::path probe_file = run / "steps" / "probe.json";
      json_file = probe_file;
      const std::string spec = field(record_of(run, "probe").summary, "fresnel", probe_file).get<std::string>();
      json_file = extract_file;
      ball.material = "glossy";
      ball.fresnel_table = "fresnel-" + name + ".exr";
      out.files[ball.fresnel_table] = fresnel_exr(spec);
      if (!have_chrome) chrome_centre = ball.centre;
      have_chrome = true;
    } else if (kind == "grey") {
      const fs::path maps = existing(run / "maps" / ("computed-" + name + ".exr"));
      ball.material = "diffuse";
      ball.colour = lambert_albedo(read_map_set(maps.string()), maps);
    } else {
      out.notes.push_back("ball '" + name + "' (" + kind + ") is left out: only chrome and grey balls are exported");
      continue;
    }
    out.balls.push_back(ball);
  }
  if (!have_chrome) throw std::invalid_argument(extract_file.string() + ": the run has no placed chrome ball");

  // The world: the probe in Blender's cell-centred equirectangular convention.
  const fs::path probe_file = existing(run / "probe.exr");
  const EnvMap probe = read_environment(probe_file.string());
  out.files["world.exr"] = world_exr(probe, options.world_width);

  // The cameras: each view's pose, its chrome cone and the lens.
  for (const ViewPose& v : poses.views) {
    if (!v.ball) {
      out.notes.push_back("view '" + v.name + "' is left out: its pose has no chrome ball to place the camera");
      continue;
    }
    const fs::path photo_file = existing(run / "hdr" / (v.name + ".exr"));
    ViewImage image = on_lens_canvas(read_view_image(photo_file.string()), lens, photo_file.string());
    BlenderCamera cam;
    cam.name = v.name;
    // The other placed balls as this view's photo shows them (the extract step's circles).
    std::vector<std::pair<Vec3, Vec3>> seen;
    for (const auto& view : summary.value("views", nlohmann::json::array()))
      if (view.value("name", "") == v.name)
        for (const auto& found : view.value("balls", nlohmann::json::array())) {
          if (found.value("status", "") != "found" || !found.contains("centre_px")) continue;
          for (const BlenderBall& ball : out.balls)
            if (ball.name == found.value("ball", "") && ball.kind != "chrome")
              seen.emplace_back(blender_from_rsibr().transpose() * ball.centre,
                                lens.unproject(Vec2(found["centre_px"][0], found["centre_px"][1])));
        }
    const Vec3 chrome_rsibr = blender_from_rsibr().transpose() * chrome_centre;
    const double distance = camera_distance(v, v.ball->distance(chrome_radius), chrome_rsibr, seen);
    // The camera centre: the chrome centre less world_from_cam * (the cone's axis at that distance).
    cam.location = blender_from_rsibr() * (chrome_rsibr - v.world_from_cam * (v.ball->axis * distance));
    cam.rotation = blender_camera_rotation(v.world_from_cam);
    cam.fx = lens.intrinsics()[0];
    cam.fy = lens.intrinsics()[1];
    cam.cx = lens.intrinsics()[2];
    cam.cy = lens.intrinsics()[3];
    cam.width = lens.width();
    cam.height = lens.height();
    cam.near = std::max(1e-4, 0.01 * chrome_radius);
    cam.far = 100 * (distance + chrome_radius);
    // An image sequence for the compositor (photo i is frame i).
    char name[32];
    std::snprintf(name, sizeof name, "photo_%04d.exr", int(out.cameras.size()) + 1);
    cam.photo = name;
    out.files[cam.photo] = rgb_exr_bytes(undistorted(image.radiance, lens));
    out.cameras.push_back(cam);
  }
  if (out.cameras.empty()) throw std::invalid_argument((run / "poses.yaml").string() + ": no view can be placed");

  const fs::path render_file = run / "steps" / "render.json";
  if (fs::is_regular_file(render_file)) {
    json_file = render_file;
    const nlohmann::json render = record_of(run, "render").summary;
    if (render.contains("display_exposure_stops")) out.exposure_stops = render["display_exposure_stops"].get<double>();
  }
  return out;
}

}  // namespace

BlenderExport blender_export_from_run(const fs::path& run, const BlenderExportOptions& options) {
  fs::path json_file = run / "steps";
  try {
    return export_from_run(run, options, json_file);
  } catch (const nlohmann::json::exception& e) {
    throw std::invalid_argument(json_file.string() + ": not a record rsibr process writes (" + e.what() + ")");
  }
}

BlenderExport blender_export_from_map_set(const MapSet& maps, const EnvMap& env, const std::string& what,
                                          const BlenderExportOptions& options) {
  if (maps.views.empty()) throw std::invalid_argument(what + ": no views");
  const std::string material = maps.views[0].material;
  for (std::size_t v = 1; v < maps.views.size(); ++v)
    if (maps.views[v].material != material)
      throw std::invalid_argument(what + ": view." + std::to_string(v) +
                                  "'s material differs from view.0's (one sphere, one material)");
  BlenderExport out;
  out.samples = options.samples;
  out.pixel_centres = true;
  BlenderBall ball;
  ball.name = "sphere";
  ball.kind = "sphere";
  ball.centre = Vec3::Zero();
  ball.radius = 1;
  ball.exact = true;  // a UV sphere's rim, seen edge-on, is 2% off at 48^2 (r > 0.9)
  const YAML::Node spec = YAML::Load(material);
  const std::string type = spec.IsMap() && spec["type"] ? spec["type"].as<std::string>() : "";
  if (type == "lambert") {
    ball.material = "diffuse";
    ball.colour = lambert_albedo(maps, what);
  } else if (type == "ggx") {
    ball.material = "glossy";
    ball.roughness = std::sqrt(spec["roughness"].as<double>());
    if (spec["fresnel"] && !(spec["fresnel"]["type"] && spec["fresnel"]["type"].as<std::string>() == "none")) {
      ball.fresnel_table = "fresnel-sphere.exr";
      YAML::Emitter e;
      e << YAML::Flow << spec["fresnel"];
      out.files[ball.fresnel_table] = fresnel_exr(e.c_str());
    }
    out.notes.push_back(
        "Cycles 3.x's GGX masks with the separable Smith form, rsibr's with the height-correlated one (up to 1% "
        "darker toward the rim of a rough ball)");
    if (!ball.fresnel_table.empty() && ball.roughness > 0)
      out.notes.push_back("the Fresnel tints by F(n.v): exact for a mirror, an approximation for a rough lobe");
  } else {
    throw std::invalid_argument(what + ": material '" + material +
                                "' has no Cycles counterpart here (Lambert and GGX are exported)");
  }
  out.balls.push_back(ball);
  out.files["world.exr"] = world_exr(env, options.world_width);
  for (std::size_t v = 0; v < maps.views.size(); ++v) {
    const MapView& mv = maps.views[v];
    BlenderCamera cam;
    cam.name = "view." + std::to_string(v);
    // The view frame (x right, y up, z toward the viewer) is a Blender camera's own frame.
    cam.rotation = blender_from_rsibr() * mv.world_from_view;
    cam.location = blender_from_rsibr() * (mv.view.normalized() * 10.0);
    cam.orthographic = 2;
    cam.width = mv.rgb.cols;
    cam.height = mv.rgb.rows;
    cam.near = 1;
    cam.far = 100;
    out.cameras.push_back(cam);
  }
  return out;
}

nlohmann::json blender_scene_json(const BlenderExport& scene) {
  auto vec = [](const Vec3& v) { return nlohmann::json::array({v.x(), v.y(), v.z()}); };
  nlohmann::json cameras = nlohmann::json::array(), balls = nlohmann::json::array();
  for (const BlenderCamera& c : scene.cameras) {
    nlohmann::json rows = nlohmann::json::array();
    for (int r = 0; r < 3; ++r) rows.push_back(vec(c.rotation.row(r).transpose()));
    nlohmann::json j = {{"name", c.name},
                        {"location", vec(c.location)},
                        {"rotation", rows},
                        {"size", {c.width, c.height}},
                        {"clip", {c.near, c.far}}};
    if (c.orthographic > 0) {
      j["orthographic_width"] = c.orthographic;
    } else {
      j["focal_px"] = {c.fx, c.fy};
      j["principal_px"] = {c.cx, c.cy};
    }
    if (!c.photo.empty()) j["photo"] = c.photo;
    cameras.push_back(j);
  }
  for (const BlenderBall& b : scene.balls) {
    nlohmann::json j = {{"name", b.name},          {"kind", b.kind},         {"centre", vec(b.centre)},
                        {"radius", b.radius},      {"material", b.material}, {"colour", vec(b.colour)},
                        {"roughness", b.roughness}};
    if (!b.fresnel_table.empty()) j["fresnel_table"] = b.fresnel_table;
    j["geometry"] = b.exact ? "exact" : "mesh";
    balls.push_back(j);
  }
  return {{"rsibr_blender_scene", 1},
          {"rsibr_version", RSIBR_VERSION},
          {"axes", "Blender's +Z-up world: rsibr's (x, y, z) is (z, x, y)"},
          {"world", {{"image", "world.exr"}, {"convention", "cell-centred equirectangular (Blender's)"}}},
          {"display", {{"exposure_stops", scene.exposure_stops}}},
          {"samples", scene.samples},
          {"pixel_filter", scene.pixel_centres ? "centre" : "area"},
          {"cameras", cameras},
          {"balls", balls},
          {"notes", scene.notes}};
}

}  // namespace rsibr
