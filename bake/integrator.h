// Lighting integrators: the radiance sphere map of a BRDF under a distant environment, for one
// view (docs/conventions.md, "Light"; formats/map_set.h).
//
// Contract of a texel (what every integrator computes). For the view v (world, unit, toward the
// viewer), the map's world_from_view T and texel p = (c, r) of a size x size sphere map whose
// centre lies inside the unit disc:
//
//   n   = T g_normal(p)                            (world, unit)
//   L_o = int_S2 L_i(w) f_r(v, w) max(0, n.w) dw  =  int_S2 L_i(w) eval(wo, wi) dw
//
// where L_i(w) is the environment radiance arriving FROM w, and wo = B^T v, wi = B^T w are v and
// w in the local frame B = shading::Frame::around(n) (n = +z, as bake/brdf.h wants; eval includes
// the cosine). Texels whose centre is outside the disc are 0. When the viewer is on or below the
// local horizon (wo.z <= 0, which happens only exactly at the rim) the texel is 0 by definition.
//
// Output: CV_32FC3, RGB, size x size. Determinism: the same inputs and seed give the same bytes,
// whatever the thread count: each texel draws its random numbers from its own counter-based stream
// keyed by (seed, texel index, sample index), never from a shared generator; texels are written
// independently.
#pragma once

#include "bake/brdf.h"
#include "bake/shading_frame.h"
#include "core/env_map.h"

#include <opencv2/core.hpp>

#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>

namespace rsibr {

struct IntegratorOptions {
  // Quality knob of the stochastic integrators (mis, fis): samples per texel (mis: this many BRDF
  // samples AND this many environment samples, combined by the balance heuristic).
  int samples = 64;
  std::uint64_t seed = 0;
  // Quality knob of the reference: the widest environment it integrates over. 0 = the full
  // environment; otherwise the finest MIP level (core/mip_pyramid.h, exact energy) whose width is
  // at most this. Cost per texel: the level's texel count.
  int reference_width = 0;
  // Filtered importance sampling: added to 0.5*log2(Omega_sample / Omega_texel). 0 since the sun is
  // split off (bake/bright_texels.h). Why 0: measured in docs/tradeoffs.md, "Measured choices in the code".
  double fis_lod_bias = 0.0;
  // Compute only the texels where this CV_8UC1 size x size mask is non-zero (others are 0); empty:
  // every texel. For error estimates on a subset (bench/bake_tradeoff.cpp): a texel's value does not
  // depend on the mask.
  cv::Mat texel_mask;
};

class Integrator {
 public:
  virtual ~Integrator() = default;
  virtual std::string name() const = 0;
  // See the contract above. Throws std::invalid_argument for unsupported BRDFs (sh: not Lambert)
  // or bad options. `progress`, if set, is called from worker threads with the number of rows done
  // so far (monotone per call, not ordered across threads).
  virtual cv::Mat radiance_map(const Brdf& brdf, const Vec3& view, const Mat3& world_from_view, int size,
                               const IntegratorOptions& options,
                               const std::function<void(int)>& progress = {}) const = 0;
};

// method: "reference", "mis", "fis" or "sh". The integrator keeps what it precomputes from env
// (pyramid, distribution, SH coefficients). Throws std::invalid_argument for unknown methods.
std::unique_ptr<Integrator> make_integrator(const std::string& method, const EnvMap& env);

namespace integrator_detail {

// Counter-based random numbers: a stateless 64-bit mix (SplitMix64 finaliser) of the key.
inline std::uint64_t mix64(std::uint64_t z) {
  z += 0x9E3779B97F4A7C15ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

// The random stream of one texel: uniform doubles in [0,1) indexed by a counter.
class TexelRng {
 public:
  TexelRng(std::uint64_t seed, std::uint64_t texel) : key_(mix64(mix64(seed) ^ (texel * 0xD1B54A32D192ED03ull))) {}
  double uniform() { return double(mix64(key_ ^ mix64(counter_++)) >> 11) * 0x1.0p-53; }
  Vec2 uniform2() {
    const double a = uniform();
    return Vec2(a, uniform());
  }

 private:
  std::uint64_t key_;
  std::uint64_t counter_ = 0;
};

// The local frame of texel (c, r) of a size x size map: nullopt when the texel is 0 by contract
// (centre outside the disc, or the viewer on or below the local horizon).
struct TexelFrame {
  shading::Frame frame;  // around the texel's world normal
  Vec3 wo;               // the view in the local frame (wo.z > 0)
};
std::optional<TexelFrame> texel_frame(int c, int r, int size, const Vec3& view, const Mat3& world_from_view);

// Van der Corput radical inverse in base 2 (bit reversal), in [0,1).
inline double radical_inverse_2(std::uint32_t i) {
  i = (i << 16) | (i >> 16);
  i = ((i & 0x55555555u) << 1) | ((i & 0xAAAAAAAAu) >> 1);
  i = ((i & 0x33333333u) << 2) | ((i & 0xCCCCCCCCu) >> 2);
  i = ((i & 0x0F0F0F0Fu) << 4) | ((i & 0xF0F0F0F0u) >> 4);
  i = ((i & 0x00FF00FFu) << 8) | ((i & 0xFF00FF00u) >> 8);
  return double(i) * 0x1.0p-32;
}

// A random permutation of [0, n) keyed by `key`, evaluated one index at a time (no table): a keyed
// invertible hash on the next power of two, cycle-walked until it lands below n (after Kensler
// 2013, "Correlated Multi-Jittered Sampling"). Used to decorrelate sample dimensions that share a
// stratified index (a pixel's sub-position and its light samples).
inline std::uint32_t permute_index(std::uint32_t i, std::uint32_t n, std::uint32_t key) {
  if (n <= 1) return 0;
  std::uint32_t w = n - 1;
  w |= w >> 1;
  w |= w >> 2;
  w |= w >> 4;
  w |= w >> 8;
  w |= w >> 16;
  do {
    i ^= key;
    i *= 0xe170893du;
    i ^= key >> 16;
    i ^= (i & w) >> 4;
    i ^= key >> 8;
    i *= 0x0929eb3fu;
    i ^= key >> 23;
    i ^= (i & w) >> 1;
    i *= 1u | key >> 27;
    i *= 0x6935fa69u;
    i ^= (i & w) >> 11;
    i *= 0x74dcb303u;
    i ^= (i & w) >> 2;
    i *= 0x9e501cc3u;
    i ^= (i & w) >> 2;
    i *= 0xc860a3dfu;
    i &= w;
    i ^= i >> 5;
  } while (i >= n);
  return (i + key) % n;
}

// Point i of the n-point Hammersley set ((i + 1/2)/n, radical_inverse_2(i)) shifted by `shift`
// modulo 1 (a Cranley-Patterson rotation: each point stays uniform on [0,1)^2, the set stays
// stratified).
inline Vec2 rotated_hammersley(int i, int n, const Vec2& shift) {
  Vec2 u((i + 0.5) / n + shift.x(), radical_inverse_2(std::uint32_t(i)) + shift.y());
  for (int k = 0; k < 2; ++k) u[k] -= std::floor(u[k]);
  return u;
}

// Runs texel(index, frame) -> RGB over every texel of a size x size map whose centre is inside the
// disc and whose wo is above the local horizon; others stay 0. Rows in parallel; result
// independent of the split.
// Texels where `mask` (IntegratorOptions::texel_mask) is zero are skipped.
cv::Mat for_each_texel(int size, const Vec3& view, const Mat3& world_from_view, const cv::Mat& mask,
                       const std::function<Vec3(long, const TexelFrame&)>& texel,
                       const std::function<void(int)>& progress);

}  // namespace integrator_detail
}  // namespace rsibr
