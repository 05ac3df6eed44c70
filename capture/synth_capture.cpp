#include "capture/synth_capture.h"
#include "formats/file_error.h"

#include "capture/camera_poses.h"
#include "capture/camera_processing.h"
#include "capture/camera_response.h"
#include "capture/chessboard.h"
#include "capture/dng_file.h"
#include "capture/irradiance.h"
#include "formats/photo_set.h"
#include "capture/rig_renderer.h"
#include "capture/sensor_noise.h"
#include "capture/true_sphere_map.h"
#include "formats/truth_image.h"
#include "formats/atomic_file.h"
#include "formats/atomic_folder.h"
#include "core/texel_audit.h"
#include "formats/written_file_check.h"
#include "formats/exr_io.h"
#include "core/patterns.h"
#include "formats/image_codecs.h"

#include <exiv2/exiv2.hpp>
#include <opencv2/imgproc.hpp>
#include <yaml-cpp/yaml.h>

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace rsibr {
namespace fs = std::filesystem;
namespace {

using Clock = std::chrono::steady_clock;
double secs(Clock::duration d) { return std::chrono::duration<double>(d).count(); }

void write_bytes(const fs::path& file, const std::vector<uchar>& bytes) {
  std::ofstream out(file, std::ios::binary);
  out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
  out.close();
  if (!out) throw FileError(file.string(), "cannot write", {}, FileRole::Output);
  check_written_file(file, file);
}

// Codes (CV_16UC1/3, RGB) -> an encoded image file of the camera's format.
void write_codes(const fs::path& file, const cv::Mat& codes, const std::string& format, int jpeg_quality = 95) {
  cv::Mat bgr;
  if (codes.channels() == 3)
    cv::cvtColor(codes, bgr, cv::COLOR_RGB2BGR);
  else
    bgr = codes;
  if (format != "tiff") bgr.convertTo(bgr, CV_8U);  // codes are already <= 255
  std::vector<uchar> bytes;
  std::vector<int> params;
  if (format == "jpeg") params = {cv::IMWRITE_JPEG_QUALITY, jpeg_quality};
  const std::string ext = format == "png" ? ".png" : format == "jpeg" ? ".jpg" : ".tif";
  if (!encode_image(ext, bgr, bytes, params)) throw std::runtime_error(file.string() + ": cannot encode");
  write_bytes(file, bytes);
}

// The EXIF a camera writes into each photo (exiv2; JPEG, PNG, TIFF and DNG): the exposure, the focal
// length (fx over the sensor's width) and its 35 mm equivalent on the diagonal, in whole mm.
void write_photo_exif(const fs::path& file, const SynthCamera& cam, double t, const SynthExposure& ex) {
  const double fx = cam.lens.intrinsics().at(0);
  const double focal_mm =
      cam.exif_focal_scale * (cam.exif_focal_mm > 0 ? cam.exif_focal_mm : fx * cam.sensor_width_mm / cam.lens.width());
  const double f35 = std::round(cam.exif_focal_scale * fx * 43.266615305567875 /
                                std::hypot(double(cam.lens.width()), double(cam.lens.height())));
  try {
    auto image = Exiv2::ImageFactory::open(file.string());
    image->readMetadata();
    Exiv2::ExifData& exif = image->exifData();
    exif["Exif.Image.Make"] = cam.make;
    if (!cam.lens_name.empty()) exif["Exif.Photo.LensModel"] = cam.lens_name;
    exif["Exif.Image.Model"] = cam.name;
    // Rationals with a fixed denominator: what cameras store (1/250 s, f/8, 35.5 mm).
    exif["Exif.Photo.ExposureTime"] = Exiv2::URational(std::uint32_t(std::lround(t * 1e6)), 1000000u);
    exif["Exif.Photo.FNumber"] = Exiv2::URational(std::uint32_t(std::lround(ex.aperture * 10)), 10u);
    exif["Exif.Photo.ISOSpeedRatings"] = std::uint16_t(std::lround(ex.iso));
    if (cam.exif_focal_scale > 0) {  // 0: the focal lengths stripped (a messaging app, a scan)
      exif["Exif.Photo.FocalLength"] = Exiv2::URational(std::uint32_t(std::lround(focal_mm * 100)), 100u);
      exif["Exif.Photo.FocalLengthIn35mmFilm"] = std::uint16_t(f35);
    }
    image->writeMetadata();
  } catch (const Exiv2::Error& e) {
    throw FileError(file.string(), std::string("cannot write EXIF: ") + e.what(), {}, FileRole::Output);
  }
}

std::string ext_of(const std::string& format) {
  return format == "png" ? "png" : format == "jpeg" ? "jpg" : format == "dng" ? "dng" : "tif";
}

// Format dng: a 14-bit sensor. Raw signal r = X / full_well in [0, 1] -> codes black + r (white - black).
constexpr int kDngBlack = 512, kDngWhite = 16383;

cv::Mat dng_codes(const cv::Mat& raw) {
  cv::Mat codes(raw.size(), CV_16UC3);
  for (int y = 0; y < raw.rows; ++y)
    for (int x = 0; x < raw.cols; ++x) {
      const cv::Vec3d r = raw.at<cv::Vec3d>(y, x);
      cv::Vec3w& o = codes.at<cv::Vec3w>(y, x);
      for (int c = 0; c < 3; ++c)
        o[c] = std::uint16_t(kDngBlack + std::lround(std::clamp(r[c], 0.0, 1.0) * (kDngWhite - kDngBlack)));
    }
  return codes;
}

// A Bayer sensor's optical low-pass filter: the birefringent plates split each ray into four
// spots a pixel apart, so a point (a sun in a chrome ball) covers every colour of the mosaic
// instead of one photosite (whose colour no demosaic could know). Modelled symmetric, [1 2 1] / 4
// per axis (the 4-dot split over the pixel's own aperture), so images do not shift.
cv::Mat optical_low_pass(const cv::Mat& L) {
  const cv::Mat k = (cv::Mat_<float>(3, 1) << 0.25f, 0.5f, 0.25f);
  cv::Mat out;
  cv::sepFilter2D(L, out, CV_32F, k, k, cv::Point(-1, -1), 0, cv::BORDER_REFLECT);
  return out;
}

// The DNG's colour: the sensor's sensitivities (no crosstalk) and the camera's white balance as
// AsShotNeutral (the raw RGB of a neutral, largest 1).
DngInfo dng_info(const SynthCamera& cam, double t, const SynthExposure& ex) {
  DngInfo d;
  d.model = cam.name;
  d.black = kDngBlack;
  d.white = kDngWhite;
  const Vec3 s = cam.processing ? cam.processing->sensitivity : Vec3::Ones();
  const Vec3 g = cam.processing ? cam.processing->gains() : Vec3::Ones();
  d.camera_from_xyz = dng_colour_matrix(s.asDiagonal().toDenseMatrix());
  const Vec3 neutral = g.cwiseInverse();
  d.as_shot_neutral = neutral / neutral.maxCoeff();
  d.exposure_s = t;
  d.iso = ex.iso;
  d.aperture = ex.aperture;
  return d;
}

// What a RAW developer recovers from that DNG (hdr/raw_image.h): gains g / min(g) on s . L, in
// linear Rec.709 (the sensor has no crosstalk, so its colour matrix is diagonal).
cv::Mat dng_linear_output(const cv::Mat& L, const SynthCamera& cam) {
  const Vec3 s = cam.processing ? cam.processing->sensitivity : Vec3::Ones();
  const Vec3 g = cam.processing ? cam.processing->gains() : Vec3::Ones();
  const Vec3 f = (g / g.minCoeff()).cwiseProduct(s);
  cv::Mat out = L.clone();
  out.forEach<cv::Vec3f>(
      [&](cv::Vec3f& p, const int*) { p = cv::Vec3f(float(p[0] * f[0]), float(p[1] * f[1]), float(p[2] * f[2])); });
  return out;
}

YAML::Node vec(const Vec3& v) {
  YAML::Node n(YAML::NodeType::Sequence);
  for (int i = 0; i < 3; ++i) n.push_back(v[i]);
  n.SetStyle(YAML::EmitterStyle::Flow);
  return n;
}
YAML::Node vec2(const Vec2& v) {
  YAML::Node n(YAML::NodeType::Sequence);
  n.push_back(v.x());
  n.push_back(v.y());
  n.SetStyle(YAML::EmitterStyle::Flow);
  return n;
}
YAML::Node mat(const Mat3& m) {
  YAML::Node n(YAML::NodeType::Sequence);
  for (int r = 0; r < 3; ++r) n.push_back(vec(m.row(r).transpose()));
  return n;
}

// v(p) = 1 - a r^2, or 1 + k1 r^2 + k2 r^4 + k3 r^6 with `poly`; r = |p - c| / |corner - c|, c the
// principal point (image centre without a core).
cv::Mat vignetting_field(const LensModel& lens, double a, const std::optional<Vec3>& poly) {
  const Vec3 k = poly.value_or(Vec3(-a, 0, 0));
  const auto& in = lens.intrinsics();
  const Vec2 c = in.size() >= 4 ? Vec2(in[2], in[3]) : Vec2(0.5 * (lens.width() - 1), 0.5 * (lens.height() - 1));
  double r2max = 0;
  for (const Vec2& k : {Vec2(-0.5, -0.5), Vec2(lens.width() - 0.5, -0.5), Vec2(-0.5, lens.height() - 0.5),
                        Vec2(lens.width() - 0.5, lens.height() - 0.5)})
    r2max = std::max(r2max, (k - c).squaredNorm());
  cv::Mat v(lens.height(), lens.width(), CV_32FC1);
  for (int y = 0; y < v.rows; ++y)
    for (int x = 0; x < v.cols; ++x) {
      const double r2 = (Vec2(x, y) - c).squaredNorm() / r2max;
      v.at<float>(y, x) = float(1 + r2 * (k[0] + r2 * (k[1] + r2 * k[2])));
    }
  return v;
}

double clipped_fraction(const cv::Mat& codes, int max_code) {
  long n = 0;
  const int ch = codes.channels();
  for (int y = 0; y < codes.rows; ++y) {
    const auto* p = codes.ptr<std::uint16_t>(y);
    for (int x = 0; x < codes.cols; ++x) {
      bool any = false;
      for (int c = 0; c < ch; ++c) any = any || p[x * ch + c] >= max_code;
      n += any;
    }
  }
  return double(n) / double(codes.total());
}

}  // namespace

EnvMap synth_environment(const SynthScene& scene) {
  const SynthEnvironment& e = scene.environment;
  EnvMap env;
  if (e.file) {
    env = read_environment(e.file->string());
    if (env.channels() > 3) {
      cv::Mat rgb;
      cv::cvtColor(env.pixels, rgb, cv::COLOR_RGBA2RGB);
      env.pixels = rgb;
    }
    const TexelAudit audit = audit_texels(env.pixels);
    const long bad = audit.nan + audit.inf + audit.huge + audit.negative;
    if (bad && !e.sanitize)
      throw std::invalid_argument(e.file->string() + ": " + std::to_string(bad) +
                                  " NaN, Inf, huge or negative values (set environment.sanitize: true to remove them)");
    if (bad) sanitize_texels(env.pixels);  // negatives folded into their neighbours, energy kept
  } else {
    env = render_pattern(
        patterns::sun_and_sky(e.sun_direction, e.sun_radius_deg * kPi / 180, e.sun_rgb, e.zenith_rgb, e.horizon_rgb),
        Layout::with_size(LayoutKind::LatLong, e.size), 4);
  }
  double brightest = 0;
  cv::minMaxLoc(env.pixels.reshape(1), nullptr, &brightest);
  if (!(brightest * e.scale <= kMaxSceneRadiance))
    throw std::invalid_argument("environment: its brightest value times scale is " +
                                std::to_string(brightest * e.scale) + ", beyond " + std::to_string(kMaxSceneRadiance) +
                                " (the camera's float arithmetic would overflow)");
  if (e.scale != 1.0) env.pixels *= e.scale;
  return env;
}

namespace {

// The capture's files written into `tmp` (the staging folder write_synth_capture renames).
SynthReport fill_synth_folder(const SynthScene& scene, const fs::path& tmp,
                              const std::function<void(double)>& progress) {
  const fs::path photos = tmp / "photos", truth = tmp / "truth";
  for (const fs::path& d : {photos / "chessboards", truth / "views", truth / "maps", truth / "chessboards"})
    fs::create_directories(d);

  const SynthCamera& cam = scene.camera;
  const std::vector<CameraPose> poses = plan_camera_poses(scene);
  // A camera inside (or touching) a ball, or whose body proxy would reach into one, sees nothing
  // sensible: refuse the spec before any work.
  for (const CameraPose& pose : poses)
    for (const SynthBall& b : scene.balls)
      if ((pose.eye - b.centre).norm() < 0.5 * b.diameter_m + 0.1)
        throw std::invalid_argument(scene.file.string() + ": " + pose.name + ": the camera is within 0.1 m of ball " +
                                    b.name + "'s surface");
  const EnvMap env = synth_environment(scene);
  const RigRenderer renderer(scene, env);
  const RayTable rays(cam.lens, 8);
  const CameraResponse response(cam.response);
  const int max_code = cam.format == "tiff" || cam.format == "dng" ? 65535 : 255;
  const std::vector<double> times = scene.exposure.times();
  auto relative_exposure = [&](double t) {
    return t * scene.exposure.iso / 100.0 / (scene.exposure.aperture * scene.exposure.aperture);
  };
  const double work = double(poses.size()) * (1 + 0.1 * double(times.size())) + 0.3 * scene.chessboards.count + 1;
  double done = 0;
  auto advance = [&](double units) {
    done += units;
    if (progress) progress(std::min(1.0, done / work));
  };

  SynthReport report;
  SensorNoise noise{1.0, cam.full_well, cam.read_noise};
  const cv::Mat vignette = vignetting_field(cam.lens, cam.vignetting, cam.vignetting_poly);
  RigRenderOptions ropt;
  ropt.supersampling = cam.supersampling;
  ropt.seed = scene.seed;

  PhotoSet set;
  set.folder = photos;
  set.camera_name = cam.name;
  for (const SynthBall& b : scene.balls)
    set.balls.push_back({b.name,
                         b.kind == "chrome" ? BallKind::chrome
                         : b.kind == "grey" ? BallKind::grey
                                            : BallKind::glossy,
                         b.diameter_m});

  YAML::Node ty;
  ty["rsibr_synth_truth"] = 1;
  ty["scene"] = scene.file.string();
  ty["seed"] = scene.seed;
  YAML::Node tc;
  tc["model"] = "camera.cameramodel";
  tc["lens"] = cam.lens.name();
  // A DNG holds the raw signal: no response is applied (the spec's names the other formats').
  tc["response"] = cam.format == "dng" ? std::string("linear") : cam.response;
  tc["response_table"] = "response.csv";
  tc["max_code"] = max_code;
  tc["format"] = cam.format;
  tc["full_well"] = cam.full_well;
  tc["read_noise"] = cam.read_noise;
  tc["shot_normalised"] = 1.0 / cam.full_well;
  tc["read_variance_normalised"] = (cam.read_noise / cam.full_well) * (cam.read_noise / cam.full_well);
  tc["vignetting"] = cam.vignetting;
  if (cam.vignetting_poly) tc["vignetting"] = vec(*cam.vignetting_poly);
  tc["white_balance"] = vec(cam.white_balance);
  if (cam.format == "jpeg") tc["jpeg_quality"] = cam.jpeg_quality;
  if (cam.processing) {
    YAML::Node tp;
    tp["sensitivity"] = vec(cam.processing->sensitivity);
    tp["white_balance_gains"] = vec(cam.processing->gains());
    tp["colour_matrix"] = mat(cam.processing->matrix());
    tp["order"] = "raw = X/full_well; w = min(1, gains * raw); m = clamp(M w, 0, 1); code = round(f(m)*max_code); JPEG";
    tp["radiance_truth"] = "views/*_radiance.exr hold M (gains * sensitivity * L): the linear output, unclipped";
    tc["processing"] = tp;
  }
  tc["supersampling"] = cam.supersampling;
  tc["convention"] =
      "X = L e k electrons (L after vignetting and white balance, e = t*iso/100/N^2); "
      "X = clamp(Poisson(X) + Normal(0, read_noise^2), 0, full_well); code = round(f(X/full_well)*max_code)";

  for (std::size_t vi = 0; vi < poses.size(); ++vi) {
    const CameraPose& pose = poses[vi];
    const auto r0 = Clock::now();
    const double before = done;
    const cv::Mat scene_radiance = renderer.render(pose, cam.lens, rays, ropt, [&](double f) {
      if (progress) progress(std::min(1.0, (before + f) / work));
    });
    report.pixels_rendered += (long long)(scene_radiance.total()) * cam.supersampling * cam.supersampling;
    advance(1);
    // L at the pixel: vignetting and white balance applied to the scene radiance (with in-camera
    // processing the sensor sees this; the truth written is the processed linear output).
    cv::Mat L(scene_radiance.size(), CV_32FC3);
    for (int y = 0; y < L.rows; ++y)
      for (int x = 0; x < L.cols; ++x) {
        const float v = vignette.at<float>(y, x);
        const cv::Vec3f s = scene_radiance.at<cv::Vec3f>(y, x);
        L.at<cv::Vec3f>(y, x) =
            cv::Vec3f(float(s[0] * v * cam.white_balance[0]), float(s[1] * v * cam.white_balance[1]),
                      float(s[2] * v * cam.white_balance[2]));
      }
    if (cam.format == "dng") L = optical_low_pass(L);
    const auto r1 = Clock::now();
    report.seconds_render += secs(r1 - r0);
    if (vi == 0) {
      // Metering on the median (a sun in the frame would drag a mean far up).
      std::vector<float> grey;
      grey.reserve(L.total());
      for (int y = 0; y < L.rows; ++y)
        for (int x = 0; x < L.cols; ++x) {
          const cv::Vec3f p = L.at<cv::Vec3f>(y, x);
          grey.push_back((p[0] + p[1] + p[2]) / 3);
        }
      std::nth_element(grey.begin(), grey.begin() + long(grey.size() / 2), grey.end());
      const double median = grey[grey.size() / 2];
      const double e_mid = relative_exposure(scene.exposure.middle_s);
      noise.gain = cam.gain.value_or(median > 0 ? 0.18 * cam.full_well / (median * e_mid) : 1.0);
      tc["gain"] = noise.gain;
      // hdr/'s normalised units (X / X_sat, X_sat = full_well): docs/conventions.md.
      tc["gain_normalised"] = noise.gain / cam.full_well;
      tc["gain_source"] =
          cam.gain ? "scene"
                   : "auto: the first view's median radiance records 18% of the full well at the middle exposure";
      report.gain = noise.gain;
    }
    PhotoView pv;
    pv.name = pose.name;
    fs::create_directories(file_in_folder(photos, pose.name));
    YAML::Node tv;
    tv["name"] = pose.name;
    tv["eye"] = vec(pose.eye);
    tv["world_from_cam"] = mat(pose.world_from_cam);
    tv["radiance"] = "views/" + pose.name + "_radiance.exr";
    tv["scene_radiance"] = "views/" + pose.name + "_scene.exr";
    for (std::size_t bi = 0; bi < times.size(); ++bi) {
      const double e = relative_exposure(times[bi]);
      const std::uint64_t stream = 1 + vi * 64 + bi;
      char name[64];
      std::snprintf(name, sizeof name, "%s_b%02zu.%s", pose.name.c_str(), bi, ext_of(cam.format).c_str());
      const fs::path file = photos / pose.name / name;
      cv::Mat codes;
      if (cam.format == "dng") {
        const Vec3 s = cam.processing ? cam.processing->sensitivity : Vec3::Ones();
        codes = dng_codes(expose_raw(L, e, noise, s, scene.seed, stream));
        write_dng(file, bayer_mosaic(codes, "RGGB"), dng_info(cam, times[bi], scene.exposure));
        write_photo_exif(file, cam, times[bi], scene.exposure);  // the EXIF IFD a camera's DNG carries
      } else {
        codes = cam.processing ? process_raw(expose_raw(L, e, noise, cam.processing->sensitivity, scene.seed, stream),
                                             *cam.processing, response, max_code)
                               : expose_bracket(L, e, noise, response, max_code, scene.seed, stream);
        write_codes(file, codes, cam.format, cam.jpeg_quality);
        write_photo_exif(file, cam, times[bi], scene.exposure);
      }
      pv.brackets.push_back({file, times[bi], scene.exposure.iso, scene.exposure.aperture});
      YAML::Node tb;
      tb["file"] = pose.name + "/" + name;
      tb["exposure_s"] = times[bi];
      tb["relative_exposure"] = e;
      tb["clipped_fraction"] = clipped_fraction(codes, cam.format == "dng" ? kDngWhite : max_code);
      tv["brackets"].push_back(tb);
      ++report.brackets;
      advance(0.1);
    }
    report.seconds_brackets += secs(Clock::now() - r1);
    const auto r2 = Clock::now();
    std::map<std::string, std::string> attrs = {{"version", RSIBR_VERSION},
                                                {"view", pose.name},
                                                {"cameraModel", cam.lens.name()},
                                                {"seed", std::to_string(scene.seed)}};
    attrs["content"] =
        cam.format == "dng"
            ? "what a RAW developer recovers: (gains / min gain) * sensitivity * L for L at the pixel: X = L e k"
        : cam.processing ? "the camera's linear output M (gains * sensitivity * L) for L at the pixel: X = L e k"
                         : "L at the pixel (after vignetting and white balance): X = L e k";
    write_truth_image(file_in_folder(truth / "views", pose.name + "_radiance.exr"),
                      cam.format == "dng" ? dng_linear_output(L, cam)
                      : cam.processing    ? linear_output(L, *cam.processing)
                                          : L,
                      &pose, attrs);
    attrs["content"] = "scene radiance along each pixel's rays (before vignetting and white balance)";
    write_truth_image(file_in_folder(truth / "views", pose.name + "_scene.exr"), scene_radiance, &pose, attrs);
    for (const SynthBall& b : scene.balls) {
      YAML::Node tb;
      tb["name"] = b.name;
      const Vec3 cam_pt = pose.world_from_cam.transpose() * (b.centre - pose.eye);
      if (cam_pt.z() > 0) tb["centre_px"] = vec2(cam.lens.project(cam_pt));
      tb["distance_m"] = cam_pt.norm();
      tv["balls"].push_back(tb);
    }
    ty["views"].push_back(tv);
    set.views.push_back(pv);
    report.seconds_truth += secs(Clock::now() - r2);
  }

  // True sphere maps: one map set per ball, a part per view.
  const auto m0 = Clock::now();
  YAML::Node tballs;
  const IrradianceQuadrature irradiance(env);
  std::unique_ptr<Integrator> fis;
  for (const SynthBall& b : scene.balls)
    if (b.kind == "glossy" && !fis) fis = make_integrator("fis", env);
  for (const SynthBall& b : scene.balls) {
    MapSet ms;
    for (const CameraPose& pose : poses)
      ms.views.push_back(true_sphere_map(b, pose.eye, env, scene.map_size, &irradiance, fis.get()));
    write_map_set(file_in_folder(truth / "maps", b.name + ".exr").string(), ms);
    YAML::Node tb;
    tb["name"] = b.name;
    tb["kind"] = b.kind;
    tb["centre"] = vec(b.centre);
    tb["diameter_m"] = b.diameter_m;
    tb["material"] = ms.views.front().material;
    tb["map"] = "maps/" + b.name + ".exr";
    tballs.push_back(tb);
  }
  ty["balls"] = tballs;
  report.seconds_truth += secs(Clock::now() - m0);
  advance(1);

  // Chessboards through the same lens, exposed like a photo (white at about 70% of the full well).
  if (scene.chessboards.count > 0) {
    ChessboardSet cs;
    cs.corners_x = cs.corners_y = scene.chessboards.corners;
    cs.spacing_m = scene.chessboards.spacing_m;
    // The camera's own response, format and white balance (boards are photographed with it), so a
    // vignetting estimate from the boards sees what the brackets see.
    const SensorNoise board_noise{0.7 * cam.full_well / 0.9, cam.full_well, cam.read_noise};
    const std::string board_ext = "." + ext_of(cam.format);
    for (int i = 0; i < scene.chessboards.count; ++i) {
      const ChessboardShot shot =
          render_chessboard(cam.lens, rays, scene.chessboards, i, scene.seed, cam.supersampling);
      const cv::Mat lit1 = shot.reflectance.mul(vignette);
      cv::Mat lit;
      cv::merge(
          std::vector<cv::Mat>{lit1 * cam.white_balance[0], lit1 * cam.white_balance[1], lit1 * cam.white_balance[2]},
          lit);
      char name[32];
      std::snprintf(name, sizeof name, "board%02d", i);
      const std::uint64_t board_stream = 0xB0000 + std::uint64_t(i);
      if (cam.format == "dng") {
        const Vec3 s = cam.processing ? cam.processing->sensitivity : Vec3::Ones();
        const cv::Mat codes = dng_codes(expose_raw(lit, 1.0, board_noise, s, scene.seed, board_stream));
        write_dng(photos / "chessboards" / (std::string(name) + board_ext), bayer_mosaic(codes, "RGGB"),
                  dng_info(cam, scene.exposure.middle_s, scene.exposure));
      } else {
        const cv::Mat codes = expose_bracket(lit, 1.0, board_noise, response, max_code, scene.seed, board_stream);
        write_codes(photos / "chessboards" / (std::string(name) + board_ext), codes, cam.format);
      }
      cs.files.push_back(photos / "chessboards" / (std::string(name) + board_ext));
      std::ostringstream corners;
      corners.precision(10);
      corners << "# true pixel positions of the inner corners, row-major (j outer, i inner); mrcal pixel convention\n";
      for (const Vec2& p : shot.corners) corners << p.x() << " " << p.y() << "\n";
      write_text_atomically(truth / "chessboards" / (std::string(name) + ".txt"), corners.str());
      YAML::Node tb;
      tb["file"] = std::string("chessboards/") + name + board_ext;
      tb["corners"] = std::string("chessboards/") + name + ".txt";
      tb["cam_from_board"] = mat(shot.cam_from_board);
      tb["board_centre_cam"] = vec(shot.board_centre_cam);
      ty["chessboards"].push_back(tb);
      ++report.chessboards;
      advance(0.3);
    }
    set.chessboards = cs;
  }

  ty["camera"] = tc;
  cam.lens.write(truth / "camera.cameramodel");
  {
    std::ostringstream csv;
    csv.precision(17);
    csv << "code,R,G,B\n";
    const CameraResponse written(cam.format == "dng" ? "linear" : cam.response);
    for (const auto& row : written.table(max_code))
      csv << row[0] << "," << row[1] << "," << row[2] << "," << row[3] << "\n";
    write_text_atomically(truth / "response.csv", csv.str());
  }
  {
    YAML::Emitter em;
    em.SetDoublePrecision(17);
    em << ty;
    write_text_atomically(
        truth / "truth.yaml",
        std::string("# Ground truth of a synthetic capture (rsibr synth); see capture/synth_capture.h.\n") +
            em.c_str() + "\n");
  }
  save_photo_set(set);
  report.views = int(poses.size());
  return report;
}

}  // namespace

SynthReport write_synth_capture(const SynthScene& scene, const fs::path& out_dir,
                                const std::function<void(double)>& progress) {
  const auto t0 = Clock::now();
  const fs::path out = fs::absolute(out_dir).lexically_normal();
  if (fs::exists(out) && !(fs::is_directory(out) && fs::is_empty(out)))
    throw std::invalid_argument(out_dir.string() + ": exists and is not an empty folder");
  if (!fs::is_directory(out.parent_path()))
    throw std::invalid_argument(out_dir.string() + ": the folder it goes in does not exist");
  const fs::path tmp = out.parent_path() / ("." + out.filename().string() + ".partial-" + std::to_string(::getpid()));
  fs::remove_all(tmp);
  struct Cleanup {
    fs::path p;
    bool keep = false;
    ~Cleanup() {
      std::error_code ec;
      if (!keep) fs::remove_all(p, ec);
    }
  } cleanup{tmp};
  try {
    SynthReport report = fill_synth_folder(scene, tmp, progress);
    if (fs::exists(out)) fs::remove(out);  // an empty folder (checked above)
    fs::rename(tmp, out);
    cleanup.keep = true;
    report.seconds_total = secs(Clock::now() - t0);
    if (progress) progress(1.0);
    return report;
  } catch (const FileError& e) {
    // Name the file where it would have been, not in the staging folder that is removed.
    std::string file = e.file();
    if (file.rfind(tmp.string(), 0) == 0) file = out.string() + file.substr(tmp.string().size());
    throw FileError(file, e.problem(), e.where(), e.role(), e.step());
  }
}

}  // namespace rsibr
