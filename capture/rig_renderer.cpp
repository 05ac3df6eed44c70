#include "capture/rig_renderer.h"

#include "bake/brdf_spec.h"
#include "bake/integrator.h"
#include "capture/irradiance.h"
#include "capture/true_sphere_map.h"
#include "core/parallel.h"

#include <atomic>
#include <cmath>
#include <limits>

namespace rsibr {

EnvMap irradiance_map(const EnvMap& env, int width) { return IrradianceQuadrature(env).latlong_map(width); }

RigRenderer::RigRenderer(const SynthScene& scene, EnvMap env) : scene_(scene), env_(std::move(env)), quadrature_(env_) {
  irradiance_ = quadrature_.latlong_map(256);
  for (const SynthBall& b : scene.balls) {
    Ball ball{b.centre, 0.5 * b.diameter_m, b.kind == "chrome", b.kind == "glossy", b.albedo, nullptr};
    if (ball.chrome) ball.fresnel = make_fresnel(YAML::Load(b.fresnel));
    if (ball.glossy && !fis_) fis_ = make_integrator("fis", env_);
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

int RigRenderer::trace(const Vec3& o, const Vec3& d, const ViewScene& view, double* t, RayHit* mesh_hit) const {
  double best = std::numeric_limits<double>::infinity();
  int ball = -2;
  for (std::size_t i = 0; i < balls_.size(); ++i)
    if (auto ti = intersect_sphere(o, d, balls_[i].centre, balls_[i].radius, 1e-9); ti && *ti < best) {
      best = *ti;
      ball = int(i);
    }
  if (view.scene && view.mesh) {
    const RayHit hit = view.scene->intersect(o, d, 1e-7, best);
    if (hit.hit && hit.t < best) {
      best = hit.t;
      ball = -1;
      *mesh_hit = hit;
    }
  }
  *t = best;
  return ball;
}

Vec3 RigRenderer::shade_mesh(const ViewScene& view, const RayHit& hit, const Vec3& d) const {
  Vec3 n = view.scene->shading_normal(hit);
  if (n.dot(d) > 0) n = -n;
  return view.mesh->albedo[hit.triangle].cwiseProduct(irradiance(n)) / kPi;
}

Vec3 RigRenderer::glossy_radiance(const ViewScene& view, std::size_t ball, const Vec3& n) const {
  // The texel of normal n holds the light reflected toward v; look it up by its mirror direction
  // (the sphere layout's direction), which is continuous up to the rim.
  const Vec3 nv = view.ball_world_from_view[ball].transpose() * n;
  const Vec3 r(2 * nv.z() * nv.x(), 2 * nv.z() * nv.y(), 2 * nv.z() * nv.z() - 1);
  float v[kMaxChannels];
  sample_bilinear(view.ball_map[ball], r, v);
  return Vec3(v[0], v[1], v[2]);
}

RigRenderer::ViewScene RigRenderer::view_scene(const RayScene* scene, const RigMesh* mesh, const Vec3& eye) const {
  ViewScene view;
  view.scene = scene;
  view.mesh = mesh;
  view.ball_irradiance.resize(balls_.size());
  view.ball_map.resize(balls_.size());
  view.ball_world_from_view.resize(balls_.size(), Mat3::Identity());
  for (std::size_t b = 0; b < balls_.size(); ++b) {
    if (!balls_[b].glossy) continue;
    const MapView mv = true_sphere_map(scene_.balls[b], eye, env_, scene_.map_size, nullptr, fis_.get());
    view.ball_map[b].layout = Layout(LayoutKind::Sphere, mv.rgb.cols, mv.rgb.rows);
    view.ball_map[b].pixels = mv.rgb;
    view.ball_world_from_view[b] = mv.world_from_view;
  }
  ViewScene unoccluded = view;  // blockers are shaded without occlusion of their own
  for (std::size_t b = 0; b < balls_.size(); ++b) {
    if (balls_[b].chrome || balls_[b].glossy) continue;
    IrradianceQuadrature q = quadrature_;
    bool any = false;
    for (std::size_t i = 0; i < q.nodes(); ++i) {
      const Vec3 w = q.node_direction(i);
      double t;
      RayHit hit;
      const int what = trace(balls_[b].centre + balls_[b].radius * w, w, unoccluded, &t, &hit);
      if (what == -2) continue;
      Vec3 L;
      if (what == -1) {
        L = shade_mesh(unoccluded, hit, w);
      } else {
        const Ball& o = balls_[std::size_t(what)];
        const Vec3 p = balls_[b].centre + balls_[b].radius * w + t * w;
        const Vec3 n = (p - o.centre).normalized();
        // A blocking ball: its Lambert radiance, or the chrome's mirror image of the environment.
        if (o.chrome)
          L = o.fresnel->eval(std::max(0.0, -w.dot(n))).cwiseProduct(environment(w - 2 * w.dot(n) * n));
        else if (o.glossy)
          L = glossy_radiance(unoccluded, std::size_t(what), n);  // as seen from the camera (approximate)
        else
          L = o.albedo.cwiseProduct(irradiance(n)) / kPi;
      }
      q.set_node_radiance(i, L);
      any = true;
    }
    view.ball_irradiance[b] = any ? q.latlong_map(256) : irradiance_;
  }
  return view;
}

Vec3 RigRenderer::radiance(const Vec3& o, const Vec3& d, const ViewScene& view, int depth) const {
  double t;
  RayHit hit;
  const int what = trace(o, d, view, &t, &hit);
  if (what == -2) return environment(d);
  if (what == -1) return shade_mesh(view, hit, d);
  const Ball& b = balls_[std::size_t(what)];
  const Vec3 p = o + t * d;
  const Vec3 n = (p - b.centre).normalized();
  if (b.glossy) return glossy_radiance(view, std::size_t(what), n);
  if (!b.chrome) {
    const EnvMap& e = view.ball_irradiance.empty() || view.ball_irradiance[std::size_t(what)].pixels.empty()
                          ? irradiance_
                          : view.ball_irradiance[std::size_t(what)];
    float v[kMaxChannels];
    sample_bilinear(e, n, v);
    return b.albedo.cwiseProduct(Vec3(v[0], v[1], v[2])) / kPi;
  }
  const double cosine = std::max(0.0, -d.dot(n));
  const Vec3 r = (d + 2 * cosine * n).normalized();
  const Vec3 f = b.fresnel->eval(cosine);
  if (depth >= 4) return f.cwiseProduct(environment(r));
  // Start the reflected ray on the surface point; t_min in the sphere test skips the start point.
  return f.cwiseProduct(radiance(b.centre + b.radius * n, r, view, depth + 1));
}

cv::Mat RigRenderer::render(const CameraPose& pose, const LensModel& lens, const RayTable& rays,
                            const RigRenderOptions& options, const std::function<void(double)>& progress) const {
  const RigMesh mesh = build_rig_mesh(scene_, &pose);
  std::unique_ptr<RayScene> scene;
  if (!mesh.mesh.triangles.empty()) scene = std::make_unique<RayScene>(mesh.mesh);
  const ViewScene view = view_scene(scene.get(), &mesh, pose.eye);
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
          sum += radiance(pose.eye, pose.world_from_cam * dc, view);
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
