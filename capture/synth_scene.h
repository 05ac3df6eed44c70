// The scene spec of `rsibr synth` (datasets-synthetic/README.md documents it with examples): an
// environment at infinity, a ball rig, a camera (lens, response, noise, vignetting, white balance,
// output format), exposure brackets, view plans and chessboards. Loading is strict
// (formats/yaml_spec.h): unknown keys, wrong types and out-of-range values are errors naming the key
// path, std::invalid_argument("<file>: <path>: <problem>").
//
// World frame: +Y up, metres. Defaults are the values the README states.
#pragma once

#include "capture/camera_processing.h"
#include "core/lens_model.h"
#include "core/vec.h"

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace rsibr {

// The brightest radiance a scene may hold (environment values, times scale): a sun 10^9 times its
// shadows fits many times over; beyond it, exposure, gains and supersampling sums in float overflow.
inline constexpr double kMaxSceneRadiance = 1e12;

struct SynthEnvironment {
  // Either a file (EXR or .hdr, path absolute after loading) ...
  std::optional<std::filesystem::path> file;
  bool sanitize = false;  // zero NaN, Inf and negative values (lossy EXR ringing) instead of failing
  // ... or an analytic sky (core/patterns.h sun_and_sky) rendered into a lat-long map.
  int size = 256;  // lat-long width of the rendered pattern
  Vec3 sun_direction = Vec3(0.4, 0.7, 0.6);
  double sun_radius_deg = 1.5;
  Vec3 sun_rgb = Vec3(2e4, 1.9e4, 1.7e4);
  Vec3 zenith_rgb = Vec3(0.25, 0.45, 1.0);
  Vec3 horizon_rgb = Vec3(1.0, 0.95, 0.85);
  double scale = 1.0;  // multiplies the environment
};

struct SynthBall {
  std::string name;
  std::string kind;  // "chrome", "grey" or "glossy"
  double diameter_m = 0.1;
  Vec3 centre = Vec3(0, 1.3, 0);
  std::string fresnel;                 // chrome: a Fresnel spec (bake/brdf_spec.h), flow YAML
  Vec3 albedo = Vec3::Constant(0.18);  // grey: Lambert albedo
  std::string brdf;                    // glossy: a BRDF spec (bake/brdf_spec.h), flow YAML, e.g. GGX with Fresnel
};

// Background objects that are not balls (the clocks, lamps, plates and spheres of real rooms that
// a ball finder must not take for a ball): Lambert, lit by the unoccluded environment, not in the
// photo set's ball list. A disc (centre, radius, normal; default: facing the rig centre) is split
// into `rings` concentric annuli alternating albedo and ring_albedo; a sphere is a tessellated mesh.
struct SynthClutter {
  std::string shape;  // "disc" or "sphere"
  Vec3 centre = Vec3::Zero();
  double radius_m = 0.2;
  std::optional<Vec3> normal;  // disc
  Vec3 albedo = Vec3::Constant(0.7);
  int rings = 1;                           // disc
  Vec3 ring_albedo = Vec3::Constant(0.1);  // disc, odd annuli
};

struct SynthViewPlan {
  std::string plan;                  // "ring", "icosa" or "handheld"
  int count = 3;                     // ring, handheld: views evenly spaced in azimuth
  std::vector<double> azimuths_deg;  // ring: explicit azimuths instead of count
  double azimuth0_deg = 0;           // first azimuth (0 = +Z, 90 = +X)
  double elevation_deg = 10;         // above the horizontal through look_at
  double min_elevation_deg = -90;    // icosa: directions below this are dropped
  double distance_m = 1.5;           // camera centre to look_at
  std::optional<Vec3> look_at;       // default: the centre of the balls
  double roll_deg = 0;
  double yaw_deg = 0;                        // after aiming: turn the camera right by this (the target moves left)
                                             // about its own y axis (aimed up or down, that tilts the horizon)
  double pan_deg = 0;                        // after aiming: turn right about the world's vertical (a person turning:
                                             // the horizon stays level)
  double jitter_m = 0.03, jitter_deg = 1.5;  // handheld: position and orientation jitter (std dev)
};

struct SynthExposure {
  double middle_s = 0.01;
  int count = 3;
  double step_ev = 2;
  double iso = 100;
  double aperture = 8;
  std::vector<double> times() const;  // shortest first
};

struct SynthCamera {
  LensModel lens = LensModel::pinhole(600, 640, 480);
  std::string name = "synthetic camera";
  std::string response = "srgb";
  std::string format = "png";  // "png" (8-bit), "jpeg" (8-bit), "tiff" (16-bit), "dng" (camera RAW:
                               // the raw signal as a 14-bit RGGB mosaic, capture/dng_file.h; no
                               // response, processing's sensitivities and white balance only)
  int jpeg_quality = 95;       // format jpeg: the encoder's quality, 1..100
  // In-camera processing (capture/camera_processing.h): raw sensitivities, white balance, colour
  // matrix, then `response` as the tone curve. Absent: codes are response(raw) per channel.
  std::optional<CameraProcessing> processing;
  int supersampling = 2;    // n: n x n stratified, jittered samples per pixel
  double vignetting = 0.0;  // v = 1 - vignetting * (r / r_corner)^2
  // Instead of that, when set: v = 1 + k1 r^2 + k2 r^4 + k3 r^6, r = |p - c| / r_corner (the
  // polynomial of lens databases; real lenses fall off faster than r^2 toward the corner).
  std::optional<Vec3> vignetting_poly;
  Vec3 white_balance = Vec3::Ones();
  double full_well = 2e4, read_noise = 3;
  std::optional<double> gain;  // electrons per unit radiance-exposure; auto (median metering) when absent
  // The sensor's width: with the lens's fx it gives the EXIF FocalLength the photos carry
  // (FocalLengthIn35mmFilm: the diagonal equivalent, in whole mm, as cameras write it).
  double sensor_width_mm = 23.5;
  std::string make = "rsibr";   // EXIF Make (with `name` as Model: a real pair lets lensfun find the camera)
  std::string lens_name;        // EXIF LensModel (empty: not written)
  double exif_focal_mm = 0;     // EXIF FocalLength; 0: fx * sensor_width_mm / width (a lensfun lens gives its own)
  double exif_focal_scale = 1;  // the EXIF's focal lengths over the lens's (a zoom's nominal focal length, focus
                                // breathing); 0: none written (stripped by a messaging app)
  std::string lensfun_lens;     // the lensfun profile the lens came from (empty: none); its vignetting
                                // at the exposure's aperture is the camera's unless `vignetting` is given
};

struct SynthChessboards {
  int count = 0;
  int corners = 10;  // inner corners along each side (mrgingham --gridn)
  double spacing_m = 0.03;
};

struct SynthScene {
  std::filesystem::path file;
  std::uint64_t seed = 1;
  SynthEnvironment environment;
  std::vector<SynthBall> balls;
  bool stand = true, photographer = true;
  std::vector<SynthClutter> clutter;
  SynthCamera camera;
  SynthExposure exposure;
  std::vector<SynthViewPlan> views;
  SynthChessboards chessboards;
  int map_size = 64;  // truth sphere maps, square

  Vec3 rig_centre() const;  // mean of the ball centres
};

SynthScene load_synth_scene(const std::filesystem::path& file);
// The same from YAML text (`what` names it in errors; relative paths resolve against `folder`).
SynthScene parse_synth_scene(const std::string& text, const std::string& what, const std::filesystem::path& folder);

}  // namespace rsibr
