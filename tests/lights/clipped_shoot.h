// Synthetic captured maps of a chrome and a grey ball with light clipped in every bracket, built
// directly from an environment (no photographs): the inputs of lights/ with a known truth.
//
//   chrome   each texel the mean over 4 x 4 points of its cell of F(n.v) L(mirror direction)
//            (what an energy-preserving extraction gives); a texel with any point above `clip`
//            (any channel) is clipped: confidence 0, `clipped` 1, value the clip level (a lower
//            bound). Elsewhere the confidence fades over the rim (n.v from cos 82 to cos 70 degrees).
//   grey     albedo E(n) / pi at the texel's normal, E by capture/irradiance.h's quadrature, times
//            (1 + noise N(0, 1)) per texel and channel, seeded; the same rim fade.
// Views: a ring of `views` directions `elevation_deg` above the horizon (world +Y up), evenly
// spaced in azimuth from `azimuth0_deg`.
#pragma once

#include "bake/brdf_spec.h"
#include "calib/probe/probe.h"
#include "lights/clipped_regions.h"
#include "capture/irradiance.h"
#include "capture/true_sphere_map.h"
#include "formats/exr_io.h"
#include "core/patterns.h"
#include "core/sphere_map.h"

#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <random>
#include <string>
#include <vector>

namespace rsibr::testing {

inline const std::filesystem::path kHdri = std::filesystem::path(RSIBR_CACHE_DIR) / "assets/hdri";

struct Disc {
  Vec3 direction;
  double radius_deg;
  Vec3 radiance;
};

// `base` (any layout, resampled bilinearly) plus the discs, in a lat-long map `width` wide
// (each texel the mean over 4 x 4 points of its cell: a disc smaller than a texel keeps its energy).
inline EnvMap environment_with(const std::optional<EnvMap>& base, const std::vector<Disc>& discs, int width = 256,
                               const Vec3& zenith = Vec3(0.25, 0.45, 1.0),
                               const Vec3& horizon = Vec3(1.0, 0.95, 0.85)) {
  std::vector<double> cos_radius;
  for (const Disc& s : discs) cos_radius.push_back(std::cos(s.radius_deg * kPi / 180));
  return render_pattern(
      [&](const Vec3& d) {
        Vec3 L;
        if (base) {
          float v[kMaxChannels];
          sample_bilinear(*base, d, v);
          L = Vec3(std::max(0.f, v[0]), std::max(0.f, v[1]), std::max(0.f, v[2]));
        } else {
          L = horizon + (zenith - horizon) * std::sqrt(std::max(0.0, d.y()));
        }
        for (std::size_t i = 0; i < discs.size(); ++i)
          if (d.dot(discs[i].direction.normalized()) >= cos_radius[i]) L += discs[i].radiance;
        return L;
      },
      Layout(LayoutKind::LatLong, width, width / 2), 4);
}

inline Vec3 direction_at(double azimuth_deg, double elevation_deg) {
  const double a = azimuth_deg * kPi / 180, e = elevation_deg * kPi / 180;
  return Vec3(std::sin(a) * std::cos(e), std::sin(e), std::cos(a) * std::cos(e));
}

inline const char* kChrome = "{type: conductor, eta: [2.9, 2.9, 2.6], k: [3.4, 3.4, 3.2]}";

struct ClippedShoot {
  MapSet chrome, grey, glossy;  // glossy: empty unless a BRDF is given
};

inline double rim_fade(double cos_nv) {
  const double t =
      std::clamp((cos_nv - std::cos(82 * kPi / 180)) / (std::cos(70 * kPi / 180) - std::cos(82 * kPi / 180)), 0.0, 1.0);
  return t * t * (3 - 2 * t);
}

// glossy: also a glossy ball of this BRDF spec (its true map: bake/'s MIS integral, 64 samples,
// the lights by exact quadrature), with the grey ball's noise and rim fade.
inline ClippedShoot clipped_shoot(const EnvMap& env, double clip, int views = 6, double elevation_deg = 10,
                                  double azimuth0_deg = 15, double noise = 0.005, int size = 64, std::uint64_t seed = 1,
                                  const std::string& glossy = "") {
  ClippedShoot shoot;
  const auto fresnel = make_fresnel(YAML::Load(kChrome));
  SynthBall grey;
  grey.name = "grey";
  grey.kind = "grey";
  grey.centre = Vec3::Zero();
  const IrradianceQuadrature irradiance(env);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> gauss(0, 1);
  std::unique_ptr<Integrator> mis;
  for (int v = 0; v < views; ++v) {
    const Vec3 view = direction_at(azimuth0_deg + 360.0 * v / views, elevation_deg);
    MapView c;
    c.view = view;
    c.world_from_view = world_from_view_for(view);
    c.source = MapSource::Captured;
    c.warp = CentralDirection::Mirror;
    c.image = "view" + std::to_string(v);
    c.rgb = cv::Mat(size, size, CV_32FC3, cv::Scalar::all(0));
    c.confidence = cv::Mat(size, size, CV_32FC1, cv::Scalar(0));
    c.clipped = cv::Mat(size, size, CV_32FC1, cv::Scalar(0));
    for (int r = 0; r < size; ++r)
      for (int col = 0; col < size; ++col) {
        const Vec2 xy = sphere_map::disc_from_pixel(Vec2(col, r), size, size);
        if (xy.squaredNorm() >= 1) continue;
        Vec3 sum = Vec3::Zero();
        bool clipped = false;
        int n = 0;
        for (int a = 0; a < 4; ++a)
          for (int b = 0; b < 4; ++b) {
            const Vec2 q =
                sphere_map::disc_from_pixel(Vec2(col - 0.5 + (b + 0.5) / 4, r - 0.5 + (a + 0.5) / 4), size, size);
            if (q.squaredNorm() >= 1) continue;
            const Vec3 nrm = c.world_from_view * sphere_map::g_normal(q);
            const double cosine = std::max(0.0, nrm.dot(view));
            float L[kMaxChannels];
            sample_bilinear(env, 2 * cosine * nrm - view, L);
            const Vec3 f = fresnel->eval(cosine);
            const Vec3 val(f[0] * L[0], f[1] * L[1], f[2] * L[2]);
            clipped = clipped || val.maxCoeff() > clip;
            sum += val, ++n;
          }
        const Vec3 centre_n = c.world_from_view * sphere_map::g_normal(xy);
        const double conf = rim_fade(centre_n.dot(view));
        const Vec3 value = clipped ? Vec3::Constant(clip) : Vec3(sum / std::max(n, 1));
        c.rgb.at<cv::Vec3f>(r, col) = cv::Vec3f(float(value[0]), float(value[1]), float(value[2]));
        if (clipped)
          c.clipped.at<float>(r, col) = float(conf);
        else
          c.confidence.at<float>(r, col) = float(conf);
      }
    shoot.chrome.views.push_back(std::move(c));

    auto captured = [&](MapView g) {
      g.source = MapSource::Captured;
      g.warp = CentralDirection::Normal;
      g.image = "view" + std::to_string(v);
      g.confidence = cv::Mat(size, size, CV_32FC1, cv::Scalar(0));
      for (int r = 0; r < size; ++r)
        for (int col = 0; col < size; ++col) {
          const Vec2 xy = sphere_map::disc_from_pixel(Vec2(col, r), size, size);
          if (xy.squaredNorm() >= 1) continue;
          cv::Vec3f& p = g.rgb.at<cv::Vec3f>(r, col);
          for (int k = 0; k < 3; ++k) p[k] = float(p[k] * (1 + noise * gauss(rng)));
          g.confidence.at<float>(r, col) = float(rim_fade(sphere_map::g_normal(xy).z()));
        }
      return g;
    };
    shoot.grey.views.push_back(captured(true_sphere_map(grey, 10 * view, env, size, &irradiance)));
    if (!glossy.empty()) {
      // bake/'s MIS integral: the bright texels (the lights) by exact quadrature, the sky sampled.
      if (!mis) mis = make_integrator("mis", env);
      MapView g;
      g.view = view;
      g.world_from_view = world_from_view_for(view);
      IntegratorOptions io;
      io.samples = 64;
      g.rgb = mis->radiance_map(*parse_brdf(glossy), view, g.world_from_view, size, io);
      shoot.glossy.views.push_back(captured(g));
    }
  }
  return shoot;
}

// The probe's options for a shoot (the chrome's Fresnel divided out), and the shoot's probe.
inline ProbeOptions probe_options(int width = 256) {
  static const auto fresnel = make_fresnel(YAML::Load(kChrome));
  ProbeOptions po;
  po.width = width;
  po.fresnel = fresnel.get();
  return po;
}
inline Probe shoot_probe(const ClippedShoot& shoot, int width = 256) {
  return assemble_probe(shoot.chrome, probe_options(width));
}

// What a recovered source had to supply (its truth): inside a cap around a clipped region (its
// radius + 2 degrees), the environment's power minus the measured probe's (the probe holds what
// the views saw unclipped at the source's edge); and the source's true direction, the
// power-weighted centroid of the environment's texels in the cap brighter than 10 x its mean.
inline std::pair<Vec3, Vec3> truth_needed(const EnvMap& env, const EnvMap& measured, const ClippedRegion& region) {
  const double cap = region.radius + 2 * kPi / 180;
  const std::vector<double> total = integral(env);
  const double mean = (total[0] + total[1] + total[2]) / (3 * 4 * kPi);
  Vec3 power = Vec3::Zero(), centroid = Vec3::Zero();
  for (const EnvMap* e : {&env, &measured})
    for (int r = 0; r < e->layout.height(); ++r)
      for (int c = 0; c < e->layout.width(); ++c) {
        const Vec3 w = e->layout.texel_direction(c, r)->normalized();
        if (angle_between(w, region.direction) > cap) continue;
        const float* L = e->pixels.ptr<float>(r) + c * e->channels();
        const double om = e->layout.texel_solid_angle(c, r);
        power += (e == &env ? om : -om) * Vec3(L[0], L[1], L[2]);
        if (e == &env && (L[0] + L[1] + L[2]) / 3 > 10 * mean) centroid += om * (L[0] + L[1] + L[2]) * w;
      }
  return {power, centroid.norm() > 0 ? Vec3(centroid.normalized()) : region.direction};
}

}  // namespace rsibr::testing
