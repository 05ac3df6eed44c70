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
// Guided sampling. Where a sun's glint dominates, a few texels carry most of the squared error and a
// uniform sample of a few hundred texels misses or over-counts them: its estimate is heavy-tailed.
// A guide (an importance q_t >= 0 per texel, e.g. |D|^2 from a cheap low-resolution bake) draws
// texels with replacement from the defensive mixture
//
//   p_t = (1 - a) / M + a q_t / sum q      (M disc texels, a = kGuideShare)
//
// and weighs each drawn texel by w_t = c_t / (p_t M) (c_t: how often it was drawn; w = c_t for a
// uniform draw), which makes sum w f an unbiased estimate of (S / M) sum over the disc of f for both
// sums of the ratio. If relative errors were the same everywhere, q = |D|^2 would make the ratio
// exact from any sample; the uniform half bounds every draw's weight by 1 / (1 - a).
//
// The estimate's standard error: a jackknife over the views (texels of one view share its glints, so
// views, not texels, are the independent units).
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
#include "formats/map_set.h"
#include "core/vec.h"
#include "core/view_set.h"
#include "runtime/blend.h"

#include <opencv2/core.hpp>

#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <vector>

namespace rsibr {

// An importance map for view k (direction `view`, frame `frame`): CV_32FC1, any square size (resized
// bilinearly to the sample's), values >= 0 and finite; read only inside the disc.
using TexelGuide = std::function<cv::Mat(int k, const Vec3& view, const Mat3& frame)>;

class ErrorSample {
 public:
  // `views` novel views (a Fibonacci lattice under a random rotation: each uniform on the sphere,
  // together evenly spread) and `texels` distinct texels of each one's size x size
  // destination disc whose normal has n . d >= min_cos, uniform among those texels; all drawn from
  // `seed`. Throws std::invalid_argument for views < 1, texels < 1, min_cos outside [0, 1) or a size
  // with fewer such texels than `texels`.
  static constexpr double kDefaultMinCos = 0.1;
  ErrorSample(int views, int texels, int size, std::uint64_t seed, double min_cos = kDefaultMinCos);
  // Guided: `texels` draws per view with replacement from the mixture above (so a view may hold
  // fewer distinct texels, each weighted). Throws std::invalid_argument as above and for a guide map
  // that is empty, not single-channel float, not square, or holds a negative or non-finite value.
  static constexpr double kGuideShare = 0.5;
  ErrorSample(int views, int texels, int size, std::uint64_t seed, const TexelGuide& guide,
              double min_cos = kDefaultMinCos);

  int size() const { return size_; }
  int view_count() const { return int(views_.size()); }
  const Vec3& view(int k) const { return views_[std::size_t(k)]; }
  const Mat3& frame(int k) const { return frames_[std::size_t(k)]; }
  // View k's texels as indices r * size + c, ascending and distinct, and their weights (all 1 for a
  // uniform sample).
  const std::vector<int>& texels(int k) const { return texels_[std::size_t(k)]; }
  const std::vector<double>& weights(int k) const { return weights_[std::size_t(k)]; }
  bool guided() const { return guided_; }
  // The world normal of view k's texel index t: T_k g_normal(its disc point).
  Vec3 normal(int k, int texel) const;
  // A CV_8UC1 size x size mask of view k's texels (the integrators' texel mask).
  cv::Mat mask(int k) const;
  // Texels in all, and the values of a vector over the sample in order (view-major, ascending).
  int count() const;
  // Views [first, last) with their texels and weights: a sample of its own whose values (direct or
  // blended) are those of the same views in this one. Throws std::invalid_argument for an empty or
  // out-of-range interval.
  ErrorSample views(int first, int last) const;

 private:
  ErrorSample() = default;
  ErrorSample(int views, int texels, int size, std::uint64_t seed, const TexelGuide* guide, double min_cos);
  int size_ = 0;
  bool guided_ = false;
  std::vector<Vec3> views_;
  std::vector<Mat3> frames_;
  std::vector<std::vector<int>> texels_;
  std::vector<std::vector<double>> weights_;
};

// A relative RMS with its standard error (the jackknife over views; 0 with one view).
struct ErrorEstimate {
  double value = 0;
  double sigma = 0;
  double upper(double k = 1.0) const { return value + k * sigma; }
};

// The ratio estimator's sums, kept per view so that samples of different views pool into one
// estimate (the views of every sample added, jackknifed together): N_k = sum_p w |B - D|^2 and
// D_k = sum_p w |D|^2 over view k's texels where the blend has weight.
class ErrorSums {
 public:
  // Appends the sample's views (values, truth and blend_weights as sample_error takes them).
  // Throws std::invalid_argument when a size differs from the sample's.
  void add(const ErrorSample& sample, const std::vector<Vec3>& values, const std::vector<Vec3>& truth,
           const std::vector<double>* blend_weights = nullptr);
  int views() const { return int(num_.size()); }
  double numerator() const;
  double denominator() const;
  // sqrt(N / D) over every view added, with the jackknife over them (sample_error's conventions).
  ErrorEstimate estimate() const;

 private:
  std::vector<double> num_, den_;
};

// The sample's estimate of the relative RMS of `values` against `truth` (both view-major over the
// sample, as direct_values and sampled_blend give them), over the texels whose blend weight is > 0
// (all when blend_weights is null), each weighted by the sample's weight. Same conventions as
// relative_rms for a zero truth. Throws std::invalid_argument when a size differs from the sample's.
ErrorEstimate sample_error(const ErrorSample& sample, const std::vector<Vec3>& values, const std::vector<Vec3>& truth,
                           const std::vector<double>* blend_weights = nullptr);

// The guide of squared radiance: each view's direct bake at guide_size x guide_size (the integrator
// with `options`, every texel), q = |rgb|^2.
TexelGuide squared_radiance_guide(const Integrator& integrator, const Brdf& brdf, const IntegratorOptions& options,
                                  int guide_size);

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

// The error (sample_error) of the blend that sampled_blend gives, measured `step` views at a time
// and stopped as soon as it provably exceeds stop_above: the estimate is sqrt(N / D), N and D sums
// over the texels where the blend has weight, so N over the views so far above stop_above^2 times
// D over every texel of the sample bounds it from below. With `prior` (the same blend's sums at
// other views), the estimate and the bound are those of the pooled views. Throws what sampled_blend
// throws and std::invalid_argument for step < 1 or a truth that is not the sample's size.
struct BlendErrorOptions {
  double stop_above = std::numeric_limits<double>::infinity();
  int step = 1;  // views per step
};
struct BlendErrorMeasure {
  std::optional<ErrorEstimate> error;  // measured at every view (pooled with the prior); nullopt: stopped
  ErrorSums sums;                      // when measured at every view: the prior's and the sample's
  double at_least = 0;                 // when stopped: the lower bound, > stop_above
  int views = 0;                       // views of the sample measured
  double seconds = 0;                  // wall time of the integration
};
BlendErrorMeasure sampled_blend_error(const Integrator& integrator, const Brdf& brdf, const IntegratorOptions& options,
                                      const ViewSet& views, int res, bool normalise_albedo, const ErrorSample& sample,
                                      const std::vector<Vec3>& truth, const BlendErrorOptions& stop,
                                      const ErrorSums& prior = {});

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
