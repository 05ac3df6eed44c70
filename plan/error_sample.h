// The error of a map set at novel views, against direct bakes there, measured at sampled texels.
//
// The metric (the one of docs/tradeoffs.md, "Warp and blend: novel views"): for K novel views d_k
// with frames T_k = world_from_view_for(d_k) and destination maps of size R, over the destination
// texels p inside the disc where the blend's weight is > 0,
//
//   rel RMS = sqrt( sum_k sum_p |B_k(p) - D_k(p)|^2 / sum_k sum_p |D_k(p)|^2 )     (|.|: RGB length)
//
// with D_k the direct bake at d_k (what an integrator gives there: the truth when it is the full
// reference quadrature) and B_k the blend of the set (runtime/blend.h). S texels per view drawn
// uniformly from the disc's texels give the ratio estimator of it.
//
// The outermost ring of the disc, where n . d < 0.1 (radius above 0.995, 1% of the disc's area), is
// left out by default: there every source is faded (the mirror direction nears -d, the singular
// direction of every map), the blend falls back to its least-faded source, and a grazing glint of a
// sun smeared along a source's rim (Fresnel near 1) gives errors of 10-20 times the map's RMS in a
// handful of texels, which would make the whole relative RMS a measure of three texels a rendered
// object shows only on its silhouette.
//
// A blend at texel p reads each located source only in the bilinear footprint of p's warped point.
// sampled_blend bakes just those texels (with a one-texel margin) through the integrator's texel
// mask: since an integrator computes a texel the same way whatever the mask (bake/integrator.h),
// the values equal those of blending the fully baked set, at a cost that does not grow with the view
// count or the map size. That is what makes a planner's pilot and a full sweep of settings cheap.
#pragma once

#include "bake/brdf.h"
#include "bake/integrator.h"
#include "core/map_set.h"
#include "core/vec.h"
#include "core/view_set.h"
#include "runtime/blend.h"

#include <opencv2/core.hpp>

#include <cstdint>
#include <vector>

namespace rsibr {

class ErrorSample {
 public:
  // `views` novel views uniform on the sphere and `texels` distinct texels of each one's size x size
  // destination disc whose normal has n . d >= min_cos, uniform among those texels; all drawn from
  // `seed`. Throws std::invalid_argument for views < 1, texels < 1, min_cos outside [0, 1) or a size
  // with fewer such texels than `texels`.
  static constexpr double kDefaultMinCos = 0.1;
  ErrorSample(int views, int texels, int size, std::uint64_t seed, double min_cos = kDefaultMinCos);

  int size() const { return size_; }
  int view_count() const { return int(views_.size()); }
  const Vec3& view(int k) const { return views_[std::size_t(k)]; }
  const Mat3& frame(int k) const { return frames_[std::size_t(k)]; }
  // View k's texels as indices r * size + c, ascending.
  const std::vector<int>& texels(int k) const { return texels_[std::size_t(k)]; }
  // The world normal of view k's texel index t: T_k g_normal(its disc point).
  Vec3 normal(int k, int texel) const;
  // A CV_8UC1 size x size mask of view k's texels (the integrators' texel mask).
  cv::Mat mask(int k) const;
  // Texels in all, and the values of a vector over the sample in order (view-major, ascending).
  int count() const;

 private:
  int size_;
  std::vector<Vec3> views_;
  std::vector<Mat3> frames_;
  std::vector<std::vector<int>> texels_;
};

// What the integrator bakes at every sampled texel (view-major): the direct bake there.
// seconds (optional) gets the wall time of the integration alone.
std::vector<Vec3> direct_values(const Integrator& integrator, const Brdf& brdf, const IntegratorOptions& options,
                                const ErrorSample& sample, double* seconds = nullptr);

struct SampledBlend {
  std::vector<Vec3> values;     // the blend at every sampled texel (view-major)
  std::vector<double> weights;  // its weight sum_i a_i there (runtime/blend.h)
  long long texels_baked = 0;   // source texels integrated (sampled_blend from an integrator)
  double seconds = 0;           // wall time of that integration
};

// The blend, at every sampled texel, of the set that bake_map_set(brdf, integrator, views, {res,
// options, normalise_albedo}) would give (bake/map_set_bake.h), integrating only the footprints.
// Throws what the integrator throws and std::invalid_argument for res < 2.
SampledBlend sampled_blend(const Integrator& integrator, const Brdf& brdf, const IntegratorOptions& options,
                           const ViewSet& views, int res, bool normalise_albedo, const ErrorSample& sample,
                           const BlendRule& rule = {});

// The blend of an existing set at every sampled texel (view_set: the set's views).
SampledBlend sampled_blend(const MapSet& set, const ViewSet& view_set, const ErrorSample& sample,
                           const BlendRule& rule = {});

// sqrt(sum |values - truth|^2 / sum |truth|^2) over the texels whose weight is > 0 (all of them
// when weights is null); 0 when the truth is 0 there and the values equal it, +Inf when only the
// truth is 0. Throws std::invalid_argument when the sizes differ.
double relative_rms(const std::vector<Vec3>& values, const std::vector<Vec3>& truth,
                    const std::vector<double>* weights = nullptr);

// Texels of a size x size sphere map whose centre lies inside the disc (what a bake integrates), or
// (min_cos > 0) whose normal has z >= min_cos.
long long disc_texel_count(int size, double min_cos = 0);

}  // namespace rsibr
