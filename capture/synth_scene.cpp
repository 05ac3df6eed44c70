#include "capture/synth_scene.h"

#include "bake/brdf_spec.h"
#include "capture/camera_response.h"
#include "core/lensfun_lens.h"
#include "core/safe_name.h"
#include "core/text.h"
#include "formats/yaml_spec.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace rsibr {
namespace {

Vec3 vec3_in(const YamlMap& m, const std::string& key, double lo, bool lo_open) {
  const Vec3 v = m.vec3(key);
  for (int i = 0; i < 3; ++i)
    spec_in_range(v[i], m.at(key) + "[" + std::to_string(i) + "]", lo, lo_open, kMaxSceneRadiance, false);
  return v;
}

SynthEnvironment parse_environment(const YAML::Node& node, const std::string& path,
                                   const std::filesystem::path& folder) {
  const YamlMap m(node, path,
                  {"file", "sanitize", "pattern", "size", "sun_direction", "sun_radius_deg", "sun_rgb", "zenith_rgb",
                   "horizon_rgb", "scale"});
  SynthEnvironment e;
  if (m.has("file") == m.has("pattern")) spec_fail(path, "give either file or pattern");
  if (m.has("file")) {
    e.file = std::filesystem::absolute(folder / m.string("file"));
    if (!std::filesystem::exists(*e.file)) spec_fail(m.at("file"), "no such file: " + e.file->string());
    if (m.has("sanitize")) e.sanitize = m.boolean("sanitize");
    for (const char* k : {"size", "sun_direction", "sun_radius_deg", "sun_rgb", "zenith_rgb", "horizon_rgb"})
      if (m.has(k)) spec_fail(m.at(k), "only for pattern: sun_and_sky");
  } else {
    m.choice("pattern", {"sun_and_sky"});
    if (m.has("sanitize")) spec_fail(m.at("sanitize"), "only for file");
    if (m.has("size")) e.size = int(spec_in_range(double(m.integer("size")), m.at("size"), 8, false, 8192, false));
    if (m.has("sun_direction")) {
      e.sun_direction = m.vec3("sun_direction");
      if (!(e.sun_direction.norm() > 0)) spec_fail(m.at("sun_direction"), "must be non-zero");
      e.sun_direction.normalize();
    }
    if (m.has("sun_radius_deg")) e.sun_radius_deg = m.number_in("sun_radius_deg", 0, false, 45, false);
    if (m.has("sun_rgb")) e.sun_rgb = vec3_in(m, "sun_rgb", 0, false);
    if (m.has("zenith_rgb")) e.zenith_rgb = vec3_in(m, "zenith_rgb", 0, false);
    if (m.has("horizon_rgb")) e.horizon_rgb = vec3_in(m, "horizon_rgb", 0, false);
  }
  if (m.has("scale")) e.scale = m.number_in("scale", 0, true, kMaxSceneRadiance, false);
  return e;
}

SynthBall parse_ball(const YAML::Node& node, const std::string& path) {
  const YamlMap m(node, path, {"name", "kind", "diameter_m", "centre", "fresnel", "albedo", "brdf"});
  SynthBall b;
  b.name = m.string("name");
  b.kind = m.choice("kind", {"chrome", "grey", "glossy"});
  if (b.kind != "glossy" && m.has("brdf")) spec_fail(m.at("brdf"), "only for kind: glossy");
  if (m.has("diameter_m")) b.diameter_m = m.positive("diameter_m");
  if (m.has("centre")) b.centre = m.vec3("centre");
  if (b.kind == "glossy") {
    if (m.has("albedo") || m.has("fresnel"))
      spec_fail(m.at(m.has("albedo") ? "albedo" : "fresnel"), "glossy balls take a brdf");
    const YAML::Node f = m.has("brdf")
                             ? m.get("brdf")
                             : YAML::Load("{type: ggx, roughness: 0.15, fresnel: {type: dielectric, ior: 1.5}}");
    b.brdf = make_brdf(f, m.at("brdf"))->spec();
  } else if (b.kind == "chrome") {
    if (m.has("albedo")) spec_fail(m.at("albedo"), "only for kind: grey");
    // Chromium-like conductor: about 57% reflectance at normal incidence (real chrome balls reflect
    // roughly 60%).
    YAML::Node f =
        m.has("fresnel") ? m.get("fresnel") : YAML::Load("{type: conductor, eta: [2.9, 2.9, 2.6], k: [3.4, 3.4, 3.2]}");
    b.fresnel = make_fresnel(f, m.at("fresnel"))->spec();
  } else {
    if (m.has("fresnel")) spec_fail(m.at("fresnel"), "only for kind: chrome");
    if (m.has("albedo")) {
      b.albedo = m.vec3("albedo");
      for (int i = 0; i < 3; ++i) spec_in_range(b.albedo[i], m.at("albedo"), 0, false, 1, false);
    }
  }
  return b;
}

// `lens: {model: lensfun, focal_mm: F, lens: NAME}`: lensfun's profile of the lens NAME (default:
// the camera's lens_name, which the photos' EXIF carries) on the camera (make, name) at F mm
// (core/lensfun_lens.h).
LensModel parse_lens(const YAML::Node& node, const std::string& path, int width, int height,
                     const std::filesystem::path& folder, SynthCamera& cam) {
  const YamlMap m(node, path, {"file", "model", "focal_px", "distortion", "intrinsics", "focal_mm", "lens"});
  if (m.has("model") && m.string("model") == "lensfun") {
    for (const char* k : {"file", "focal_px", "distortion", "intrinsics"})
      if (m.has(k)) spec_fail(m.at(k), "not with model: lensfun (the profile gives the lens)");
    const double focal_mm = m.number_in("focal_mm", 0, false, 2000, false);
    std::string why;
    const std::string name = m.has("lens") ? valid_utf8(m.string("lens")) : cam.lens_name;
    const std::optional<LensfunLens> L = lensfun_lens(cam.make, cam.name, name, focal_mm, width, height, &why);
    if (!L) spec_fail(path, why + " (camera make and name, and lens or the camera's lens_name, name them)");
    cam.exif_focal_mm = focal_mm;
    cam.lensfun_lens = name;
    return L->lens;
  }
  for (const char* k : {"focal_mm", "lens"})
    if (m.has(k)) spec_fail(m.at(k), "only with model: lensfun");
  if (m.has("file")) {
    for (const char* k : {"model", "focal_px", "distortion", "intrinsics"})
      if (m.has(k)) spec_fail(m.at(k), "not with file");
    LensModel lens = LensModel::read(folder / m.string("file"));
    if (lens.width() != width || lens.height() != height)
      spec_fail(m.at("file"), "its image size differs from camera.width x camera.height");
    return lens;
  }
  const std::string model = m.string("model");
  std::vector<double> intr;
  if (m.has("intrinsics")) {
    if (m.has("focal_px") || m.has("distortion")) spec_fail(m.at("intrinsics"), "give intrinsics or focal_px");
    intr = m.numbers("intrinsics");
  } else {
    // Under 1 px a pinhole's pixels span most of a half-space: no camera, and no ray table.
    const double f = m.number_in("focal_px", 1, false, 1e7, false);
    intr = {f, f, 0.5 * (width - 1), 0.5 * (height - 1)};
    if (m.has("distortion"))
      for (double d : m.numbers("distortion")) intr.push_back(d);
  }
  try {
    return LensModel(model, intr, width, height);
  } catch (const std::invalid_argument& e) {
    spec_fail(path, e.what());
  }
}

CameraProcessing parse_processing(const YAML::Node& node, const std::string& path) {
  const YamlMap m(node, path, {"sensitivity", "white_balance", "saturation", "colour_matrix"});
  CameraProcessing p;
  if (m.has("sensitivity")) p.sensitivity = vec3_in(m, "sensitivity", 0, true);
  if (m.has("white_balance")) {
    const YAML::Node wb = m.get("white_balance");
    if (!(wb.IsScalar() && wb.as<std::string>() == "auto")) p.white_balance = vec3_in(m, "white_balance", 0, true);
  }
  if (m.has("saturation")) p.saturation = m.number_in("saturation", 0, false, 4, false);
  if (m.has("colour_matrix")) {
    if (m.has("saturation")) spec_fail(m.at("colour_matrix"), "give colour_matrix or saturation");
    const std::vector<double> v = m.numbers("colour_matrix");
    if (v.size() != 9) spec_fail(m.at("colour_matrix"), "9 numbers, row by row");
    Mat3 M;
    for (int i = 0; i < 9; ++i) M(i / 3, i % 3) = v[std::size_t(i)];
    p.colour_matrix = M;
  }
  return p;
}

SynthCamera parse_camera(const YAML::Node& node, const std::string& path, const std::filesystem::path& folder) {
  const YamlMap m(node, path,
                  {"name", "width", "height", "lens", "response", "format", "jpeg_quality", "processing",
                   "supersampling", "vignetting", "white_balance", "full_well", "read_noise", "gain", "sensor_width_mm",
                   "make", "lens_name", "exif_focal_scale"});
  SynthCamera c;
  const int w = int(spec_in_range(double(m.integer("width")), m.at("width"), 16, false, 16384, false));
  const int h = int(spec_in_range(double(m.integer("height")), m.at("height"), 16, false, 16384, false));
  if (m.has("name")) c.name = valid_utf8(m.string("name"));  // free text (bytes that are not UTF-8 replaced)
  if (m.has("make")) c.make = valid_utf8(m.string("make"));
  if (m.has("lens_name")) c.lens_name = valid_utf8(m.string("lens_name"));
  c.lens = parse_lens(m.get("lens"), m.at("lens"), w, h, folder, c);
  if (c.lens.can_project_behind_camera())
    spec_fail(m.at("lens"), "models that see behind the camera (stereographic, splined) are not supported yet");
  if (m.has("response")) c.response = m.choice("response", CameraResponse::kinds());
  if (m.has("format")) c.format = m.choice("format", {"png", "jpeg", "tiff", "dng"});
  if (c.format == "dng" && (w % 2 || h % 2))
    spec_fail(m.at("format"), "dng needs an even width and height (a 2x2 Bayer pattern)");
  if (m.has("jpeg_quality")) {
    if (c.format != "jpeg") spec_fail(m.at("jpeg_quality"), "only for format: jpeg");
    c.jpeg_quality = int(spec_in_range(double(m.integer("jpeg_quality")), m.at("jpeg_quality"), 1, false, 100, false));
  }
  if (m.has("processing")) c.processing = parse_processing(m.get("processing"), m.at("processing"));
  if (m.has("supersampling"))
    c.supersampling =
        int(spec_in_range(double(m.integer("supersampling")), m.at("supersampling"), 1, false, 16, false));
  if (m.has("vignetting")) {
    if (m.get("vignetting").IsSequence()) {
      const Vec3 k = m.vec3("vignetting");
      // v must stay in (0.02, 1.5] from the centre to the corner.
      for (int i = 0; i <= 100; ++i) {
        const double r2 = i / 100.0, v = 1 + k[0] * r2 + k[1] * r2 * r2 + k[2] * r2 * r2 * r2;
        if (!(v > 0.02 && v <= 1.5))
          spec_fail(m.at("vignetting"), "the polynomial leaves (0.02, 1.5] inside the image");
      }
      c.vignetting_poly = k;
    } else {
      c.vignetting = m.number_in("vignetting", 0, false, 1, true);
    }
  }
  if (m.has("exif_focal_scale")) {
    c.exif_focal_scale = m.number_in("exif_focal_scale", 0, false, 2, false);
    if (c.exif_focal_scale > 0 && c.exif_focal_scale < 0.5)
      spec_fail(m.at("exif_focal_scale"), "0 (no focal length in the EXIF) or 0.5 to 2");
  }
  if (m.has("white_balance")) c.white_balance = vec3_in(m, "white_balance", 0, true);
  if (m.has("full_well")) c.full_well = m.number_in("full_well", 1, false, 1e9, false);
  if (m.has("read_noise")) c.read_noise = m.number_in("read_noise", 0, false, 1e6, false);
  if (m.has("gain")) c.gain = m.positive("gain");
  if (m.has("sensor_width_mm")) c.sensor_width_mm = m.number_in("sensor_width_mm", 1, false, 100, false);
  return c;
}

SynthClutter parse_clutter(const YAML::Node& node, const std::string& path) {
  const YamlMap m(node, path, {"shape", "centre", "radius_m", "normal", "albedo", "rings", "ring_albedo"});
  SynthClutter c;
  c.shape = m.choice("shape", {"disc", "sphere"});
  c.centre = m.vec3("centre");
  if (m.has("radius_m")) c.radius_m = m.positive("radius_m");
  auto albedo = [&](const char* key) {
    const Vec3 a = m.vec3(key);
    for (int i = 0; i < 3; ++i) spec_in_range(a[i], m.at(key) + "[" + std::to_string(i) + "]", 0, false, 1, false);
    return a;
  };
  if (m.has("albedo")) c.albedo = albedo("albedo");
  if (c.shape == "sphere")
    for (const char* k : {"normal", "rings", "ring_albedo"})
      if (m.has(k)) spec_fail(m.at(k), "only for shape: disc");
  if (m.has("normal")) {
    c.normal = m.vec3("normal");
    if (!(c.normal->norm() > 0)) spec_fail(m.at("normal"), "must be non-zero");
    c.normal->normalize();
  }
  if (m.has("rings")) c.rings = int(spec_in_range(double(m.integer("rings")), m.at("rings"), 1, false, 64, false));
  if (m.has("ring_albedo")) c.ring_albedo = albedo("ring_albedo");
  return c;
}

SynthViewPlan parse_plan(const YAML::Node& node, const std::string& path) {
  const YamlMap m(node, path,
                  {"plan", "count", "azimuths_deg", "azimuth0_deg", "elevation_deg", "min_elevation_deg", "distance_m",
                   "look_at", "roll_deg", "yaw_deg", "pan_deg", "jitter_m", "jitter_deg"});
  SynthViewPlan p;
  p.plan = m.choice("plan", {"ring", "icosa", "handheld"});
  auto only = [&](const char* key, std::initializer_list<const char*> plans) {
    if (!m.has(key)) return false;
    for (const char* q : plans)
      if (p.plan == q) return true;
    spec_fail(m.at(key), "not a key of plan: " + p.plan);
  };
  if (only("count", {"ring", "handheld"}))
    p.count = int(spec_in_range(double(m.integer("count")), m.at("count"), 1, false, 1000, false));
  if (only("azimuths_deg", {"ring"})) {
    if (m.has("count")) spec_fail(m.at("azimuths_deg"), "give count or azimuths_deg");
    p.azimuths_deg = m.numbers("azimuths_deg");
    if (p.azimuths_deg.empty()) spec_fail(m.at("azimuths_deg"), "must not be empty");
  }
  if (only("azimuth0_deg", {"ring", "handheld"})) p.azimuth0_deg = m.number("azimuth0_deg");
  if (only("elevation_deg", {"ring", "handheld"}))
    p.elevation_deg = m.number_in("elevation_deg", -89, false, 89, false);
  if (only("min_elevation_deg", {"icosa"}))
    p.min_elevation_deg = m.number_in("min_elevation_deg", -90, false, 90, false);
  if (m.has("distance_m")) p.distance_m = m.positive("distance_m");
  if (m.has("look_at")) p.look_at = m.vec3("look_at");
  if (m.has("roll_deg")) p.roll_deg = m.number_in("roll_deg", -180, false, 180, false);
  if (m.has("yaw_deg")) p.yaw_deg = m.number_in("yaw_deg", -89, false, 89, false);
  if (m.has("pan_deg")) p.pan_deg = m.number_in("pan_deg", -89, false, 89, false);
  if (only("jitter_m", {"handheld"})) p.jitter_m = m.number_in("jitter_m", 0, false, 10, false);
  if (only("jitter_deg", {"handheld"})) p.jitter_deg = m.number_in("jitter_deg", 0, false, 45, false);
  return p;
}

SynthScene parse_root(const YAML::Node& root, const std::filesystem::path& folder) {
  const YamlMap m(root, "scene",
                  {"rsibr_synth", "seed", "environment", "balls", "stand", "photographer", "camera", "exposure",
                   "views", "chessboards", "truth_map_size", "clutter"});
  if (m.integer("rsibr_synth") != 1) spec_fail(m.at("rsibr_synth"), "unsupported version (expected 1)");
  SynthScene s;
  if (m.has("seed"))
    s.seed = std::uint64_t(spec_in_range(double(m.integer("seed")), m.at("seed"), 0, false, 9e15, false));
  s.environment = parse_environment(m.get("environment"), m.at("environment"), folder);
  const YAML::Node balls = m.get("balls");
  if (!balls.IsSequence() || balls.size() == 0) spec_fail(m.at("balls"), "expected a non-empty list");
  DistinctNames names;  // names become file names (truth/maps/<name>.exr)
  for (std::size_t i = 0; i < balls.size(); ++i) {
    const std::string p = m.at("balls") + "[" + std::to_string(i) + "]";
    s.balls.push_back(parse_ball(balls[i], p));
    names.add(s.balls.back().name, p + ".name", "ball");
  }
  for (std::size_t i = 0; i < s.balls.size(); ++i)
    for (std::size_t j = 0; j < i; ++j)
      if ((s.balls[i].centre - s.balls[j].centre).norm() < 0.5 * (s.balls[i].diameter_m + s.balls[j].diameter_m))
        spec_fail(m.at("balls") + "[" + std::to_string(i) + "]", "overlaps ball " + s.balls[j].name);
  if (m.has("stand")) s.stand = m.boolean("stand");
  if (m.has("photographer")) s.photographer = m.boolean("photographer");
  if (m.has("clutter")) {
    const YAML::Node cl = m.get("clutter");
    if (!cl.IsSequence()) spec_fail(m.at("clutter"), "expected a list");
    for (std::size_t i = 0; i < cl.size(); ++i)
      s.clutter.push_back(parse_clutter(cl[i], m.at("clutter") + "[" + std::to_string(i) + "]"));
  }
  s.camera = parse_camera(m.get("camera"), m.at("camera"), folder);
  if (m.has("exposure")) {
    const YamlMap e(m.get("exposure"), m.at("exposure"), {"middle_s", "count", "step_ev", "iso", "aperture"});
    if (e.has("middle_s")) s.exposure.middle_s = e.positive("middle_s");
    if (e.has("count"))
      s.exposure.count = int(spec_in_range(double(e.integer("count")), e.at("count"), 1, false, 32, false));
    if (e.has("step_ev")) s.exposure.step_ev = e.number_in("step_ev", 0, true, 8, false);
    if (e.has("iso")) s.exposure.iso = e.positive("iso");
    if (e.has("aperture")) s.exposure.aperture = e.positive("aperture");
  }
  // A lens from lensfun vignettes as its profile says at this aperture (focused at 1 m).
  const YAML::Node cam_node = m.get("camera");
  if (!s.camera.lensfun_lens.empty() && !(cam_node.IsMap() && cam_node["vignetting"])) {
    const SynthCamera& c = s.camera;
    if (const auto v = lensfun_vignetting(c.make, c.name, c.lensfun_lens, c.exif_focal_mm, s.exposure.aperture,
                                          c.lens.width(), c.lens.height()))
      s.camera.vignetting_poly = Vec3(v->k[0], v->k[1], v->k[2]);
  }
  const YAML::Node views = m.get("views");
  if (!views.IsSequence() || views.size() == 0) spec_fail(m.at("views"), "expected a non-empty list of plans");
  for (std::size_t i = 0; i < views.size(); ++i)
    s.views.push_back(parse_plan(views[i], m.at("views") + "[" + std::to_string(i) + "]"));
  if (m.has("chessboards")) {
    const YamlMap c(m.get("chessboards"), m.at("chessboards"), {"count", "corners", "spacing_m"});
    s.chessboards.count = int(spec_in_range(double(c.integer("count")), c.at("count"), 0, false, 1000, false));
    if (c.has("corners"))
      s.chessboards.corners = int(spec_in_range(double(c.integer("corners")), c.at("corners"), 2, false, 64, false));
    if (c.has("spacing_m")) s.chessboards.spacing_m = c.positive("spacing_m");
  }
  if (m.has("truth_map_size"))
    s.map_size = int(spec_in_range(double(m.integer("truth_map_size")), m.at("truth_map_size"), 8, false, 4096, false));
  return s;
}

}  // namespace

std::vector<double> SynthExposure::times() const {
  std::vector<double> t;
  for (int i = 0; i < count; ++i) t.push_back(middle_s * std::exp2(step_ev * (i - 0.5 * (count - 1))));
  return t;
}

Vec3 SynthScene::rig_centre() const {
  Vec3 c = Vec3::Zero();
  for (const SynthBall& b : balls) c += b.centre;
  return balls.empty() ? c : c / double(balls.size());
}

SynthScene parse_synth_scene(const std::string& text, const std::string& what, const std::filesystem::path& folder) {
  try {
    SynthScene s = parse_root(parse_yaml(text, what), folder);
    s.file = what;
    return s;
  } catch (const YAML::Exception& e) {
    throw std::invalid_argument(what + ":" + std::to_string(e.mark.line + 1) + ":" + std::to_string(e.mark.column + 1) +
                                ": " + e.msg);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(what + ": " + e.what());
  }
}

SynthScene load_synth_scene(const std::filesystem::path& file) {
  const YAML::Node root = load_yaml_file(file);
  try {
    SynthScene s = parse_root(root, std::filesystem::absolute(file).parent_path());
    s.file = std::filesystem::absolute(file);
    return s;
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(file.string() + ": " + e.what());
  }
}

}  // namespace rsibr
