#include "capture/true_sphere_map.h"

#include "bake/brdf_spec.h"
#include "capture/irradiance.h"
#include "core/parallel.h"
#include "core/sphere_map.h"

#include <optional>
#include <sstream>

namespace rsibr {

MapView true_sphere_map(const SynthBall& ball, const Vec3& camera_centre, const EnvMap& env, int size,
                        const IrradianceQuadrature* irradiance_in, const Integrator* fis) {
  MapView mv;
  mv.view = (camera_centre - ball.centre).normalized();
  mv.world_from_view = world_from_view_for(mv.view);
  mv.source = MapSource::Computed;
  mv.attributes["version"] = RSIBR_VERSION;
  mv.attributes["ball"] = ball.name;
  mv.attributes["kind"] = ball.kind;
  mv.attributes["truth"] = "synthetic capture";
  if (ball.kind == "chrome") {
    mv.warp = CentralDirection::Mirror;
    mv.material = "{type: mirror, fresnel: " + ball.fresnel + "}";
    const auto fresnel = make_fresnel(YAML::Load(ball.fresnel));
    mv.rgb = cv::Mat::zeros(size, size, CV_32FC3);
    parallel_for_rows(size, [&](int r) {
      for (int c = 0; c < size; ++c) {
        const Vec2 xy = sphere_map::disc_from_pixel(Vec2(c, r), size, size);
        if (xy.squaredNorm() >= 1) continue;
        const Vec3 n = mv.world_from_view * sphere_map::g_normal(xy);
        const double cosine = std::max(0.0, n.dot(mv.view));
        const Vec3 dir = 2 * cosine * n - mv.view;
        float L[kMaxChannels];
        sample_bilinear(env, dir, L);
        const Vec3 F = fresnel->eval(cosine);
        float* px = mv.rgb.ptr<float>(r) + 3 * c;
        for (int k = 0; k < 3; ++k) px[k] = float(F[k] * L[k]);
      }
    });
  } else if (ball.kind == "glossy") {
    const auto brdf = parse_brdf(ball.brdf);
    mv.material = brdf->spec();
    mv.warp = brdf->central_direction();
    std::unique_ptr<Integrator> own;
    if (!fis) own = make_integrator("fis", env);
    IntegratorOptions options;
    options.samples = 64;
    options.seed = 0;
    mv.rgb = (fis ? fis : own.get())->radiance_map(*brdf, mv.view, mv.world_from_view, size, options);
    mv.attributes["method"] = "fis";
    mv.attributes["samples"] = "64";
  } else {
    mv.warp = CentralDirection::Normal;
    std::ostringstream spec;
    spec.precision(17);
    spec << "{type: lambert, albedo: [" << ball.albedo.x() << ", " << ball.albedo.y() << ", " << ball.albedo.z()
         << "]}";
    mv.material = parse_brdf(spec.str())->spec();
    // Lambert: L_o = albedo E(n) / pi (the integral of bake/'s LambertBrdf against the environment).
    std::optional<IrradianceQuadrature> own;
    if (!irradiance_in) own.emplace(env);
    const IrradianceQuadrature& irradiance = irradiance_in ? *irradiance_in : *own;
    mv.rgb = cv::Mat::zeros(size, size, CV_32FC3);
    parallel_for_rows(size, [&](int r) {
      for (int c = 0; c < size; ++c) {
        const Vec2 xy = sphere_map::disc_from_pixel(Vec2(c, r), size, size);
        if (xy.squaredNorm() >= 1) continue;
        const Vec3 e = ball.albedo.cwiseProduct(irradiance(mv.world_from_view * sphere_map::g_normal(xy))) / kPi;
        float* px = mv.rgb.ptr<float>(r) + 3 * c;
        for (int k = 0; k < 3; ++k) px[k] = float(e[k]);
      }
    });
    mv.attributes["method"] = "irradiance quadrature (capture/irradiance.h)";
  }
  return mv;
}

}  // namespace rsibr
