#include "capture/rig_renderer.h"

#include "bake/brdf_spec.h"
#include "bake/integrator.h"
#include "capture/irradiance.h"
#include "core/parallel.h"

#include <atomic>
#include <cmath>
#include <limits>

namespace rsibr {

EnvMap irradiance_map(const EnvMap& env, int width) { return IrradianceQuadrature(env).latlong_map(width); }

RigRenderer::RigRenderer(const SynthScene& scene, EnvMap env) : scene_(scene), env_(std::move(env)) {
  irradiance_ = irradiance_map(env_);
  for (const SynthBall& b : scene.balls) {
    Ball ball{b.centre, 0.5 * b.diameter_m, b.kind == "chrome", b.albedo, nullptr};
    if (ball.chrome) ball.fresnel = make_fresnel(YAML::Load(b.fresnel));
    balls_.push_back(ball);
  }
}

Vec3 RigRenderer::environment(const Vec3& d) const {
  float v[kMaxChannels];
  sample_bilinear(env_, d, v);
  return Vec3(v[0], v[1], v[2]);
}

Vec3 RigRenderer::irradiance(const Vec3& n) const {
  float v[kMaxChannels];
  sample_bilinear(irradiance_, n, v);
  return Vec3(v[0], v[1], v[2]);
}

Vec3 RigRenderer::radiance(const Vec3& o, const Vec3& d, const RayScene* scene, const RigMesh* mesh, int depth) const {
  double best = std::numeric_limits<double>::infinity();
  int ball = -1;
  for (std::size_t i = 0; i < balls_.size(); ++i)
    if (auto t = intersect_sphere(o, d, balls_[i].centre, balls_[i].radius, 1e-9); t && *t < best) {
      best = *t;
      ball = int(i);
    }
  if (scene && mesh) {
    const RayHit hit = scene->intersect(o, d, 1e-7, best);
    if (hit.hit && hit.t < best) {
      Vec3 n = scene->shading_normal(hit);
      if (n.dot(d) > 0) n = -n;
      return mesh->albedo[hit.triangle].cwiseProduct(irradiance(n)) / kPi;
    }
  }
  if (ball < 0) return environment(d);
  const Ball& b = balls_[std::size_t(ball)];
  const Vec3 p = o + best * d;
  const Vec3 n = (p - b.centre).normalized();
  if (!b.chrome) return b.albedo.cwiseProduct(irradiance(n)) / kPi;
  const double cosine = std::max(0.0, -d.dot(n));
  const Vec3 r = (d + 2 * cosine * n).normalized();
  const Vec3 f = b.fresnel->eval(cosine);
  if (depth >= 4) return f.cwiseProduct(environment(r));
  // Start the reflected ray on the surface point; t_min in the sphere test skips the start point.
  return f.cwiseProduct(radiance(b.centre + b.radius * n, r, scene, mesh, depth + 1));
}

cv::Mat RigRenderer::render(const CameraPose& pose, const LensModel& lens, const RayTable& rays,
                            const RenderOptions& options, const std::function<void(double)>& progress) const {
  const RigMesh mesh = build_rig_mesh(scene_, &pose);
  std::unique_ptr<RayScene> scene;
  if (!mesh.mesh.triangles.empty()) scene = std::make_unique<RayScene>(mesh.mesh);
  const int w = lens.width(), h = lens.height(), n = options.supersampling;
  cv::Mat out(h, w, CV_32FC3);
  std::atomic<int> rows_done{0};
  parallel_for_rows(h, [&](int y) {
    for (int x = 0; x < w; ++x) {
      integrator_detail::TexelRng rng(options.seed, std::uint64_t(y) * std::uint64_t(w) + std::uint64_t(x));
      Vec3 sum = Vec3::Zero();
      for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
          const double u = options.jitter ? rng.uniform() : 0.5, v = options.jitter ? rng.uniform() : 0.5;
          const Vec3 dc = rays.direction(x - 0.5 + (i + u) / n, y - 0.5 + (j + v) / n);
          sum += radiance(pose.eye, pose.world_from_cam * dc, scene.get(), &mesh);
        }
      sum /= double(n * n);
      float* px = out.ptr<float>(y) + 3 * x;
      for (int k = 0; k < 3; ++k) px[k] = float(sum[k]);
    }
    const int done = ++rows_done;
    if (progress) progress(double(done) / h);
  });
  return out;
}

}  // namespace rsibr
