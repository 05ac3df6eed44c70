#include "bake/reference_renderer.h"

#include "bake/integrator.h"
#include "bake/mis_integrator.h"
#include "bake/shading_frame.h"
#include "core/parallel.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <stdexcept>

namespace rsibr {

Background parse_background(const std::string& text) {
  if (text == "env") return Background::Environment;
  if (text == "black") return Background::Black;
  throw std::invalid_argument("background must be 'env' or 'black', not '" + text + "'");
}

std::string to_string(Background b) { return b == Background::Environment ? "env" : "black"; }

namespace {

Vec3 texel_rgb(const float* p, int channels) { return channels >= 3 ? Vec3(p[0], p[1], p[2]) : Vec3::Constant(p[0]); }

}  // namespace

ReferenceLighting::ReferenceLighting(const EnvMap& env)
    : original_(env),
      latlong_(as_latlong(env)),
      dist_(latlong_),
      split_(split_bright_texels(latlong_)),
      remainder_dist_(split_.remainder) {
  const int ch = latlong_.channels(), w = latlong_.layout.width();
  radiance_.resize(static_cast<std::size_t>(latlong_.layout.texel_count()));
  remainder_radiance_.resize(radiance_.size());
  for (int r = 0; r < latlong_.layout.height(); ++r) {
    const float* row = latlong_.pixels.ptr<float>(r);
    const float* rest = split_.remainder.pixels.ptr<float>(r);
    for (int c = 0; c < w; ++c) {
      radiance_[std::size_t(r) * w + c] = texel_rgb(row + c * ch, ch);
      remainder_radiance_[std::size_t(r) * w + c] = texel_rgb(rest + c * ch, ch);
    }
  }
}

Vec3 ReferenceLighting::background(const Vec3& d) const {
  float out[kMaxChannels] = {};
  sample_bilinear(original_, d, out);
  return texel_rgb(out, original_.channels());
}

namespace {

// The local shading frame at a hit seen from direction v (unit, from the hit toward the viewer),
// with the normal policy of the header comment applied.
struct Surface {
  Vec3 x;                // position (world)
  Vec3 ng;               // geometric normal turned toward the viewer (world, unit)
  shading::Frame frame;  // around the shading normal
  Vec3 wo;               // v in the local frame; wo.z >= kMinViewCosine except when n had to fall back to n_g
};

Surface surface_at(const RayScene& scene, const RayHit& hit, const Vec3& v) {
  Surface s;
  s.x = scene.position(hit);
  s.ng = scene.geometric_normal(hit);
  Vec3 n = scene.shading_normal(hit);
  if (s.ng.dot(v) < 0) s.ng = -s.ng;
  if (n.dot(s.ng) < 0) n = -n;  // the shading normal on the viewer's side of the surface
  const double c = n.dot(v);
  if (!(c >= kMinViewCosine)) {
    //   n = c v + p (p perpendicular to v)  ->  n' = c0 v + sqrt(1 - c0^2) p/|p|   (c0 = kMinViewCosine)
    const Vec3 p = n - c * v;
    const double len = p.norm();
    if (len > 1e-12 && std::isfinite(len))
      n = kMinViewCosine * v + std::sqrt(1.0 - kMinViewCosine * kMinViewCosine) * (p / len);
    else
      n = s.ng;
    n.normalize();
  }
  s.frame = shading::Frame::around(n);
  s.wo = s.frame.to_local(v);
  return s;
}

struct Counts {
  long hits = 0, shadow_rays = 0, bounce_rays = 0;
};

}  // namespace

ReferenceImage render_reference(const RayScene& scene, const Brdf& brdf, const ReferenceLighting& lighting,
                                const Camera& camera, const ReferenceOptions& options,
                                const std::function<void(int)>& progress) {
  if (options.spp < 1) throw std::invalid_argument("reference: spp must be >= 1");
  if (options.light_samples < 1) throw std::invalid_argument("reference: light samples must be >= 1");
  if (options.bounces < 1) throw std::invalid_argument("reference: bounces must be >= 1");
  if (camera.width < 1 || camera.height < 1) throw std::invalid_argument("reference: empty image");

  const Eigen::AlignedBox3f box = scene.mesh().bounds();
  double eps = options.ray_epsilon;
  if (!(eps > 0)) {
    const double extent =
        box.isEmpty() ? 1.0
                      : std::max<double>(box.diagonal().norm(),
                                         std::max(box.min().cwiseAbs().maxCoeff(), box.max().cwiseAbs().maxCoeff()));
    eps = 1e-4 * std::max(extent, 1e-30);
  }
  const bool shadows = options.shadows;
  const int bounces = shadows ? options.bounces : 1;
  const int spp = options.spp, K = options.light_samples, n_first = spp * K;
  const double inv_k = 1.0 / K;
  const int W = camera.width, H = camera.height;

  ReferenceImage out;
  out.rgb = cv::Mat(H, W, CV_32FC3, cv::Scalar::all(0));
  out.alpha = cv::Mat(H, W, CV_32FC1, cv::Scalar::all(0));
  std::vector<Counts> row_counts(static_cast<std::size_t>(H));
  std::atomic<int> rows_done{0};

  parallel_for_rows(H, [&](int r) {
    Counts counts;
    cv::Vec3f* rgb_row = out.rgb.ptr<cv::Vec3f>(r);
    float* alpha_row = out.alpha.ptr<float>(r);
    for (int c = 0; c < W; ++c) {
      integrator_detail::TexelRng rng(options.seed, std::uint64_t(r) * std::uint64_t(W) + std::uint64_t(c));
      const Vec2 shift_pixel = rng.uniform2(), shift_b = rng.uniform2(), shift_e = rng.uniform2();
      // The light samples of sub-pixel sample s use a per-pixel random permutation of the index:
      // with the same index in both, the light sample would be a function of the sub-pixel
      // position and the pixel would converge to a seed-dependent value.
      const auto key_b = std::uint32_t(rng.uniform() * 4294967296.0),
                 key_e = std::uint32_t(rng.uniform() * 4294967296.0);
      Vec3 pixel = Vec3::Zero();
      int covered = 0;
      for (int s = 0; s < spp; ++s) {
        const Vec2 u = integrator_detail::rotated_hammersley(s, spp, shift_pixel);
        Vec3 dir = camera.ray_direction(c - 0.5 + u.x(), r - 0.5 + u.y());
        RayHit hit = scene.intersect(camera.eye, dir);
        if (!hit.hit) {
          if (options.background == Background::Environment) pixel += lighting.background(dir);
          continue;
        }
        ++covered;
        Vec3 beta = Vec3::Ones();  // path throughput
        Vec3 radiance = Vec3::Zero();
        for (int depth = 0;; ++depth) {
          const Surface S = surface_at(scene, hit, -dir);
          const Vec3 origin = S.x + eps * S.ng;
          const bool may_continue = depth + 1 < bounces;
          // The sun split where a cluster level fits this lobe: clusters as point lights (one
          // shadow ray each), MIS over the remainder; otherwise MIS over the whole environment.
          const BrightClusterLevel* level =
              lighting.split().bright.empty() ? nullptr : cluster_level_for(lighting.split(), brdf.lobe_width(S.wo));
          const EnvironmentDistribution& dist = level ? lighting.remainder_distribution() : lighting.distribution();
          auto env_radiance = [&](long texel) -> const Vec3& {
            return level ? lighting.remainder_radiance(texel) : lighting.radiance(texel);
          };
          if (level) {
            for (const BrightCluster& cl : level->clusters) {
              const Vec3 wi = S.frame.to_local(cl.dir);
              if (!(wi.z() > 0)) continue;
              const Vec3 f = brdf.eval(S.wo, wi);
              if (f == Vec3::Zero()) continue;
              if (shadows) {
                if (cl.dir.dot(S.ng) <= 0) continue;
                ++counts.shadow_rays;
                if (scene.occluded(origin, cl.dir)) continue;
              }
              radiance += beta.cwiseProduct(f.cwiseProduct(cl.power));
            }
          }
          bool next = false;
          Vec3 next_dir, next_weight;
          RayHit next_hit;
          for (int k = 0; k < K; ++k) {
            // The first interaction is stratified over the pixel's spp x K samples; deeper ones
            // draw from the pixel's stream (only reached with shadows and bounces > 1).
            Vec2 ub, ue;
            if (depth == 0) {
              const auto index = std::uint32_t(s * K + k), count = std::uint32_t(n_first);
              ub = integrator_detail::rotated_hammersley(int(integrator_detail::permute_index(index, count, key_b)),
                                                         n_first, shift_b);
              ue = integrator_detail::rotated_hammersley(int(integrator_detail::permute_index(index, count, key_e)),
                                                         n_first, shift_e);
            } else {
              ub = rng.uniform2();
              ue = rng.uniform2();
            }
            // BRDF sample: L(w) eval / (p_b + p_e).
            const BrdfSample b = brdf.sample(S.wo, ub);
            if (b.valid) {
              const Vec3 w = S.frame.to_world(b.wi);
              bool escapes = true;
              if (shadows) {
                if (w.dot(S.ng) <= 0) {
                  escapes = false;  // blocked by the surface itself
                } else if (k == 0 && may_continue) {
                  const RayHit h = scene.intersect(origin, w);
                  ++counts.bounce_rays;
                  if (h.hit) {
                    escapes = false;
                    next = true;
                    next_dir = w;
                    next_weight = b.weight;
                    next_hit = h;
                  }
                } else {
                  ++counts.shadow_rays;
                  escapes = !scene.occluded(origin, w);
                }
              }
              if (escapes) {
                const Vec3 f = brdf.eval(S.wo, b.wi);
                radiance +=
                    inv_k * beta.cwiseProduct(f.cwiseProduct(env_radiance(dist.texel_of(w)))) / (b.pdf + dist.pdf(w));
              }
            }
            // Environment sample: L(w) eval / (p_b + p_e).
            const EnvironmentDistribution::Sample e = dist.sample(ue);
            if (e.pdf > 0) {
              const Vec3 wi = S.frame.to_local(e.dir);
              if (wi.z() > 0) {
                const Vec3 f = brdf.eval(S.wo, wi);
                if (f != Vec3::Zero()) {
                  bool visible = true;
                  if (shadows) {
                    if (e.dir.dot(S.ng) <= 0) {
                      visible = false;
                    } else {
                      ++counts.shadow_rays;
                      visible = !scene.occluded(origin, e.dir);
                    }
                  }
                  if (visible)
                    radiance +=
                        inv_k * beta.cwiseProduct(f.cwiseProduct(env_radiance(e.texel))) / (brdf.pdf(S.wo, wi) + e.pdf);
                }
              }
            }
          }
          if (!next) break;
          beta = beta.cwiseProduct(next_weight);
          dir = next_dir;
          hit = next_hit;
        }
        pixel += radiance;
      }
      counts.hits += covered;
      pixel /= spp;
      rgb_row[c] = cv::Vec3f(float(pixel.x()), float(pixel.y()), float(pixel.z()));
      alpha_row[c] = float(covered) / float(spp);
    }
    row_counts[std::size_t(r)] = counts;
    const int done = ++rows_done;
    if (progress) progress(done);
  });

  out.samples = long(W) * long(H) * spp;
  for (const Counts& k : row_counts) {
    out.hits += k.hits;
    out.shadow_rays += k.shadow_rays;
    out.bounce_rays += k.bounce_rays;
  }
  return out;
}

ReferenceImage render_reference(const RayScene& scene, const Brdf& brdf, const EnvMap& env, const Camera& camera,
                                const ReferenceOptions& options, const std::function<void(int)>& progress) {
  const ReferenceLighting lighting(env);
  return render_reference(scene, brdf, lighting, camera, options, progress);
}

}  // namespace rsibr
