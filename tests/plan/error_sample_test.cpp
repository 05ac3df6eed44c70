#include "plan/error_sample.h"

#include "bake/brdf_spec.h"
#include "bake/integrator.h"
#include "bake/map_set_bake.h"
#include "core/patterns.h"
#include "core/sphere_map.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <set>

namespace rsibr {
namespace {

EnvMap sky(const Vec3& sun) {
  return render_pattern(
      patterns::sun_and_sky(sun.normalized(), 0.08, Vec3(400, 380, 300), Vec3(0.3, 0.5, 1.0), Vec3(0.9, 0.8, 0.6)),
      Layout(LayoutKind::LatLong, 64, 32), 2);
}

TEST(ErrorSample, TexelsAreDistinctInsideTheDiscAndTheSameForTheSameSeed) {
  const ErrorSample a(3, 50, 32, 7), b(3, 50, 32, 7), c(3, 50, 32, 8);
  ASSERT_EQ(a.count(), 150);
  bool differs = false;
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(a.view(k).norm(), 1.0, 1e-12);
    EXPECT_EQ(a.texels(k), b.texels(k));
    differs = differs || a.texels(k) != c.texels(k);
    const std::set<int> distinct(a.texels(k).begin(), a.texels(k).end());
    EXPECT_EQ(distinct.size(), 50u);
    for (int t : a.texels(k)) EXPECT_LT(sphere_map::disc_from_pixel(Vec2(t % 32, t / 32), 32, 32).squaredNorm(), 1.0);
    EXPECT_EQ(cv::countNonZero(a.mask(k)), 50);
  }
  EXPECT_TRUE(differs);
}

TEST(ErrorSample, MoreTexelsThanTheDiscHoldsAreRefused) {
  EXPECT_THROW(ErrorSample(1, int(disc_texel_count(8)) + 1, 8, 0, 0.0), std::invalid_argument);
  EXPECT_NO_THROW(ErrorSample(1, int(disc_texel_count(8)), 8, 0, 0.0));
  EXPECT_THROW(ErrorSample(1, int(disc_texel_count(8, 0.5)) + 1, 8, 0, 0.5), std::invalid_argument);
  EXPECT_LT(disc_texel_count(64, 0.1), disc_texel_count(64));
  EXPECT_THROW(ErrorSample(1, 1, 8, 0, 1.0), std::invalid_argument);
  EXPECT_EQ(disc_texel_count(2), 4);
  EXPECT_EQ(disc_texel_count(1), 1);
}

TEST(ErrorSample, NormalsAreTheDestinationFramesNormalsAndLeaveOutTheGrazingRing) {
  const ErrorSample s(4, 300, 64, 3);
  double lowest = 1;
  for (int k = 0; k < s.view_count(); ++k)
    for (int t : s.texels(k)) {
      const Vec3 n = s.normal(k, t);
      EXPECT_NEAR(n.norm(), 1.0, 1e-12);
      lowest = std::min(lowest, n.dot(s.view(k)));
    }
  EXPECT_GE(lowest, ErrorSample::kDefaultMinCos - 1e-12);
  EXPECT_LT(lowest, 0.2);  // the sample reaches close to the ring it leaves out
}

// The footprint trick is exact: blending the set baked only where the blend reads gives the blend of
// the whole set, texel for texel (mirror and normal warps, with and without albedo normalisation).
void expect_footprints_equal_the_whole_set(const std::string& spec, bool normalise) {
  const EnvMap env = sky(Vec3(0.3, 0.8, 0.2));
  const auto brdf = parse_brdf(spec);
  const auto integrator = make_integrator("fis", env);
  const ViewSet views = ViewSet::named("42");
  MapSetBakeOptions o;
  o.res = 24;
  o.integrator.samples = 16;
  o.normalise_albedo = normalise;
  // Sizes even and odd, coarser and finer than the sample's; the sample reaches the rim ring.
  for (int res : {24, 61}) {
    o.res = res;
    const MapSet whole = bake_map_set(*brdf, *integrator, views, o);
    const ErrorSample sample(6, 60, 48, 11);
    const SampledBlend full = sampled_blend(whole, views, sample);
    const SampledBlend sparse = sampled_blend(*integrator, *brdf, o.integrator, views, o.res, normalise, sample);
    ASSERT_EQ(full.values.size(), sparse.values.size());
    for (std::size_t i = 0; i < full.values.size(); ++i) {
      EXPECT_EQ(full.values[i], sparse.values[i]) << spec << " size " << res << " texel " << i;
      EXPECT_EQ(full.weights[i], sparse.weights[i]);
    }
    EXPECT_GT(sparse.texels_baked, 0);
    EXPECT_LT(sparse.texels_baked, 42LL * res * res / 2);  // a fraction of the set
  }
}

TEST(SampledBlend, FootprintsGiveTheBlendOfTheWholeSetMirrorWarp) {
  expect_footprints_equal_the_whole_set("{type: ggx, roughness: 0.3, fresnel: {type: schlick, f0: [0.9, 0.6, 0.5]}}",
                                        false);
}

TEST(SampledBlend, FootprintsGiveTheBlendOfTheWholeSetNormalWarp) {
  expect_footprints_equal_the_whole_set("{type: lambert, albedo: [0.8, 0.7, 0.6]}", false);
}

TEST(SampledBlend, FootprintsGiveTheBlendOfTheWholeSetAlbedoNormalised) {
  expect_footprints_equal_the_whole_set("{type: ggx, roughness: 0.4, fresnel: {type: schlick, f0: [0.04, 0.04, 0.04]}}",
                                        true);
}

// A part of a sample is a sample of its own: its views, texels and weights, and so its blended and
// direct values, are those of the same views in the whole; empty or out-of-range parts are refused.
TEST(ErrorSample, APartOfTheViewsGivesTheWholesValuesForThoseViews) {
  const EnvMap env = sky(Vec3(0.2, 0.9, -0.3));
  const auto brdf = parse_brdf("{type: ggx, roughness: 0.25, fresnel: {type: schlick, f0: [0.9, 0.8, 0.6]}}");
  const auto integrator = make_integrator("fis", env);
  IntegratorOptions o;
  o.samples = 8;
  const ErrorSample whole(5, 30, 32, 3, squared_radiance_guide(*integrator, *brdf, o, 16));
  const ErrorSample part = whole.views(2, 4);
  ASSERT_EQ(part.view_count(), 2);
  EXPECT_TRUE(part.guided());
  std::size_t offset = 0;
  for (int k = 0; k < 2; ++k) offset += whole.texels(k).size();
  const ViewSet views = ViewSet::named("42");
  const SampledBlend bw = sampled_blend(*integrator, *brdf, o, views, 24, false, whole);
  const SampledBlend bp = sampled_blend(*integrator, *brdf, o, views, 24, false, part);
  const std::vector<Vec3> dw = direct_values(*integrator, *brdf, o, whole),
                          dp = direct_values(*integrator, *brdf, o, part);
  ASSERT_EQ(std::size_t(part.count()), whole.texels(2).size() + whole.texels(3).size());
  ASSERT_EQ(bp.values.size(), std::size_t(part.count()));
  for (int k = 0; k < 2; ++k) {
    EXPECT_EQ(part.view(k), whole.view(k + 2));
    EXPECT_EQ(part.texels(k), whole.texels(k + 2));
    EXPECT_EQ(part.weights(k), whole.weights(k + 2));
  }
  for (std::size_t i = 0; i < bp.values.size(); ++i) {
    EXPECT_EQ(bp.values[i], bw.values[offset + i]);
    EXPECT_EQ(bp.weights[i], bw.weights[offset + i]);
    EXPECT_EQ(dp[i], dw[offset + i]);
  }
  EXPECT_THROW(whole.views(3, 3), std::invalid_argument);
  EXPECT_THROW(whole.views(-1, 2), std::invalid_argument);
  EXPECT_THROW(whole.views(4, 6), std::invalid_argument);
}

// Measured a few views at a time (and pooled with a prior of other views), the blend's error is the
// whole estimate unless it provably exceeds the bound: then the measurement stops with a lower bound
// between the bound and the whole estimate.
TEST(SampledBlendError, StopsOnlyWhenTheErrorProvablyExceedsTheBoundAndElseIsTheWholeEstimate) {
  const EnvMap env = sky(Vec3(-0.3, 0.7, 0.4));
  const auto brdf = parse_brdf("{type: ggx, roughness: 0.2, fresnel: {type: schlick, f0: [0.9, 0.8, 0.6]}}");
  const auto fis = make_integrator("fis", env);
  const auto reference = make_integrator("reference", env);
  IntegratorOptions o;
  o.samples = 16;
  const ErrorSample sample(12, 40, 32, 9, squared_radiance_guide(*fis, *brdf, o, 16));
  const std::vector<Vec3> truth = direct_values(*reference, *brdf, IntegratorOptions{}, sample);
  const ViewSet views = ViewSet::named("icosa");
  const SampledBlend b = sampled_blend(*fis, *brdf, o, views, 16, false, sample);
  const ErrorEstimate whole = sample_error(sample, b.values, truth, &b.weights);
  ASSERT_GT(whole.value, 0.01);
  BlendErrorOptions never;
  never.step = 5;  // 12 views in steps of 5, 5 and 2
  const BlendErrorMeasure all = sampled_blend_error(*fis, *brdf, o, views, 16, false, sample, truth, never);
  ASSERT_TRUE(all.error);
  EXPECT_EQ(all.error->value, whole.value);
  EXPECT_EQ(all.error->sigma, whole.sigma);
  EXPECT_EQ(all.views, 12);
  BlendErrorOptions above{whole.value * 1.001, 1};
  const BlendErrorMeasure kept = sampled_blend_error(*fis, *brdf, o, views, 16, false, sample, truth, above);
  ASSERT_TRUE(kept.error);
  EXPECT_EQ(kept.error->value, whole.value);
  BlendErrorOptions half{whole.value / 2, 1};
  const BlendErrorMeasure stopped = sampled_blend_error(*fis, *brdf, o, views, 16, false, sample, truth, half);
  ASSERT_FALSE(stopped.error);
  EXPECT_LT(stopped.views, 12);
  EXPECT_GT(stopped.at_least, whole.value / 2);
  EXPECT_LE(stopped.at_least, whole.value);
  // Pooled: the first 7 views' sums as the prior of the last 5 give the whole estimate, and a stop
  // there bounds the pooled estimate.
  const ErrorSample head = sample.views(0, 7), tail = sample.views(7, 12);
  const std::vector<Vec3> head_truth(truth.begin(), truth.begin() + head.count());
  const std::vector<Vec3> tail_truth(truth.begin() + head.count(), truth.end());
  const BlendErrorMeasure first = sampled_blend_error(*fis, *brdf, o, views, 16, false, head, head_truth, never);
  ASSERT_TRUE(first.error);
  EXPECT_EQ(first.sums.views(), 7);
  const BlendErrorMeasure pooled =
      sampled_blend_error(*fis, *brdf, o, views, 16, false, tail, tail_truth, never, first.sums);
  ASSERT_TRUE(pooled.error);
  EXPECT_EQ(pooled.views, 5);
  EXPECT_EQ(pooled.sums.views(), 12);
  EXPECT_DOUBLE_EQ(pooled.error->value, whole.value);
  EXPECT_DOUBLE_EQ(pooled.error->sigma, whole.sigma);
  const BlendErrorMeasure pooled_stop =
      sampled_blend_error(*fis, *brdf, o, views, 16, false, tail, tail_truth, half, first.sums);
  ASSERT_FALSE(pooled_stop.error);
  EXPECT_EQ(pooled_stop.views, 1);  // the prior's numerator counts from the first step
  EXPECT_GT(pooled_stop.at_least, whole.value / 2);
  EXPECT_LE(pooled_stop.at_least, whole.value);
  BlendErrorOptions bad{1.0, 0};
  EXPECT_THROW(sampled_blend_error(*fis, *brdf, o, views, 16, false, sample, truth, bad), std::invalid_argument);
  const std::vector<Vec3> short_truth(truth.begin(), truth.end() - 1);
  EXPECT_THROW(sampled_blend_error(*fis, *brdf, o, views, 16, false, sample, short_truth, never),
               std::invalid_argument);
}

TEST(SampledBlend, ABlendAtItsOwnViewsIsTheDirectBake) {
  // Novel views that are the set's views: the blend returns each source, so the error is float
  // rounding alone.
  const EnvMap env = sky(Vec3(-0.2, 0.5, 0.8));
  const auto brdf = parse_brdf("{type: lambert, albedo: [0.5, 0.5, 0.5]}");
  const auto integrator = make_integrator("reference", env);
  const ErrorSample sample(2, 30, 32, 5);
  std::vector<Vec3> own;
  for (int k = 0; k < sample.view_count(); ++k) own.push_back(sample.view(k));
  own.push_back(Vec3(0, 1, 0));
  own.push_back(Vec3(0, -1, 0));
  own.push_back(Vec3(1, 0, 0));
  own.push_back(Vec3(-1, 0, 0.1));
  const ViewSet views(own);
  IntegratorOptions o;
  const std::vector<Vec3> direct = direct_values(*integrator, *brdf, o, sample);
  const SampledBlend b = sampled_blend(*integrator, *brdf, o, views, 32, false, sample);
  EXPECT_LT(relative_rms(b.values, direct, &b.weights), 1e-5);
}

TEST(RelativeRms, IsZeroForEqualVectorsAndScalesWithTheError) {
  const std::vector<Vec3> truth = {Vec3(1, 2, 3), Vec3(0, 1, 0)};
  EXPECT_EQ(relative_rms(truth, truth), 0.0);
  std::vector<Vec3> off = truth;
  for (Vec3& v : off) v *= 1.1;
  EXPECT_NEAR(relative_rms(off, truth), 0.1, 1e-12);
  const std::vector<double> weights = {0.0, 1.0};
  off[0] = Vec3(100, 100, 100);  // weight 0: left out
  EXPECT_NEAR(relative_rms(off, truth, &weights), 0.1, 1e-12);
  EXPECT_EQ(relative_rms({Vec3(0, 0, 0)}, {Vec3(0, 0, 0)}), 0.0);
  EXPECT_TRUE(std::isinf(relative_rms({Vec3(1, 0, 0)}, {Vec3(0, 0, 0)})));
  EXPECT_THROW(relative_rms(truth, {Vec3(1, 1, 1)}), std::invalid_argument);
}

// A synthetic glint for the sampling tests: the truth over the sphere of normals is a dim sky with a
// bright narrow lobe; the values hold the lobe a little displaced, by an amount that depends on the
// view (as a blend of glints errs), so a few texels on the lobe's flanks in some views hold all of
// the error.
const Vec3 kGlint = Vec3(0.3, 0.5, 0.8).normalized();
Vec3 glint_truth(const Vec3& n) { return Vec3(1, 1, 1) * (1.0 + 200.0 * std::exp((n.dot(kGlint) - 1.0) / 0.01)); }
Vec3 glint_value(const Vec3& n, const Vec3& view) {
  return glint_truth((n + 0.04 * view.cross(kGlint)).normalized()).cwiseProduct(Vec3(1.0, 0.95, 0.9));
}

struct Evaluated {
  std::vector<Vec3> values, truth;
};
Evaluated evaluate(const ErrorSample& s) {
  Evaluated e;
  for (int k = 0; k < s.view_count(); ++k)
    for (int t : s.texels(k)) {
      e.values.push_back(glint_value(s.normal(k, t), s.view(k)));
      e.truth.push_back(glint_truth(s.normal(k, t)));
    }
  return e;
}
// The guide of the glint's squared truth, as squared_radiance_guide would give it from a bake.
TexelGuide glint_guide(int size) {
  return [size](int, const Vec3&, const Mat3& frame) {
    cv::Mat q(size, size, CV_32FC1, cv::Scalar(0));
    for (int r = 0; r < size; ++r)
      for (int c = 0; c < size; ++c) {
        const Vec2 d = sphere_map::disc_from_pixel(Vec2(c, r), size, size);
        if (d.squaredNorm() >= 1) continue;
        q.at<float>(r, c) = float(glint_truth(frame * sphere_map::g_normal(d)).squaredNorm());
      }
    return q;
  };
}
// The exact relative RMS over the whole domain of the same views.
double whole_disc_error(const ErrorSample& s) {
  double num = 0, den = 0;
  const ErrorSample all(s.view_count(), int(disc_texel_count(s.size(), ErrorSample::kDefaultMinCos)), s.size(), 0);
  for (int k = 0; k < s.view_count(); ++k)
    for (int t : all.texels(k)) {
      const Vec3 n = (s.frame(k) * sphere_map::g_normal(sphere_map::disc_from_pixel(Vec2(t % s.size(), t / s.size()),
                                                                                    s.size(), s.size())))
                         .normalized();
      num += (glint_value(n, s.view(k)) - glint_truth(n)).squaredNorm();
      den += glint_truth(n).squaredNorm();
    }
  return std::sqrt(num / den);
}

TEST(GuidedSample, TexelsAreDistinctAscendingAndEachDrawWeighsAtMostTheUniformShare) {
  const int S = 200;
  const ErrorSample s(4, S, 32, 3, glint_guide(16));
  EXPECT_TRUE(s.guided());
  for (int k = 0; k < s.view_count(); ++k) {
    ASSERT_EQ(s.texels(k).size(), s.weights(k).size());
    EXPECT_TRUE(std::is_sorted(s.texels(k).begin(), s.texels(k).end()));
    EXPECT_EQ(std::set<int>(s.texels(k).begin(), s.texels(k).end()).size(), s.texels(k).size());
    EXPECT_LT(s.texels(k).size(), std::size_t(S));  // the glint's texels are drawn more than once
    // w = c / (p M) with p >= (1 - a) / M; the counts c sum to S.
    double bound = 0;
    for (double w : s.weights(k)) {
      EXPECT_GT(w, 0.0);
      bound += w * (1.0 - ErrorSample::kGuideShare);
    }
    EXPECT_LE(bound, double(S) + 1e-9);
  }
  const ErrorSample uniform(2, 50, 32, 3);
  EXPECT_FALSE(uniform.guided());
  for (int k = 0; k < 2; ++k)
    for (double w : uniform.weights(k)) EXPECT_EQ(w, 1.0);
}

TEST(GuidedSample, BadGuidesAreRefused) {
  auto constant = [](float v, int size, int type = CV_32FC1) {
    return TexelGuide([=](int, const Vec3&, const Mat3&) { return cv::Mat(size, size, type, cv::Scalar::all(v)); });
  };
  EXPECT_THROW(ErrorSample(1, 10, 16, 0, constant(-1.0f, 16)), std::invalid_argument);
  EXPECT_THROW(ErrorSample(1, 10, 16, 0, constant(std::numeric_limits<float>::quiet_NaN(), 16)), std::invalid_argument);
  EXPECT_THROW(ErrorSample(1, 10, 16, 0, constant(1.0f, 16, CV_8UC1)), std::invalid_argument);
  EXPECT_THROW(ErrorSample(1, 10, 16, 0, TexelGuide([](int, const Vec3&, const Mat3&) { return cv::Mat(); })),
               std::invalid_argument);
  // A guide of zeros leaves the uniform draw, with replacement: every weight is the texel's count.
  const ErrorSample zero(1, 30, 16, 0, constant(0.0f, 16));
  double sum = 0;
  for (double w : zero.weights(0)) {
    EXPECT_NEAR(w, std::round(w), 1e-9);
    sum += w;
  }
  EXPECT_NEAR(sum, 30.0, 1e-9);
}

// The weights make both sums of the ratio unbiased: over many draws the guided estimate of the
// error converges to the whole-disc value, and with far less scatter than a uniform sample of the
// same size, since the glint's few texels are drawn densely.
TEST(GuidedSample, TheGuidedEstimateConvergesToTheWholeDiscAndScattersLessThanAUniformOne) {
  const int draws = 300, views = 4, texels = 40, size = 48;
  std::vector<double> guided, uniform;
  double truth_mean = 0;
  for (int d = 0; d < draws; ++d) {
    const ErrorSample g(views, texels, size, 1000 + d, glint_guide(24));
    const ErrorSample u(views, texels, size, 1000 + d);
    const Evaluated eg = evaluate(g), eu = evaluate(u);
    guided.push_back(std::pow(sample_error(g, eg.values, eg.truth).value, 2));
    uniform.push_back(std::pow(sample_error(u, eu.values, eu.truth).value, 2));
    if (d < 40) truth_mean += std::pow(whole_disc_error(g), 2) / 40.0;
  }
  auto mean = [](const std::vector<double>& v) { return std::accumulate(v.begin(), v.end(), 0.0) / double(v.size()); };
  auto sd = [&](const std::vector<double>& v) {
    const double m = mean(v);
    double ss = 0;
    for (double x : v) ss += (x - m) * (x - m);
    return std::sqrt(ss / double(v.size() - 1));
  };
  // The ratio of means is biased at O(1/n); within 10% of the whole disc's mean squared error here.
  EXPECT_NEAR(mean(guided), truth_mean, 0.1 * truth_mean);
  EXPECT_LT(sd(guided), 0.5 * sd(uniform));
}

// The jackknife over views is an honest standard error: its typical value covers the scatter of the
// estimate over independent draws, and is not uselessly loose (the views are spread evenly, which
// the jackknife, treating them as independent, does not credit: it errs high).
TEST(GuidedSample, TheJackknifeSigmaCoversTheScatterOverDraws) {
  const int draws = 200;
  std::vector<double> values;
  double sigma2 = 0;
  for (int d = 0; d < draws; ++d) {
    const ErrorSample g(12, 30, 32, 5000 + d, glint_guide(16));
    const Evaluated e = evaluate(g);
    const ErrorEstimate est = sample_error(g, e.values, e.truth);
    values.push_back(est.value);
    sigma2 += est.sigma * est.sigma / draws;
  }
  const double m = std::accumulate(values.begin(), values.end(), 0.0) / draws;
  double ss = 0;
  for (double v : values) ss += (v - m) * (v - m);
  const double scatter = std::sqrt(ss / (draws - 1));
  EXPECT_GT(std::sqrt(sigma2) / scatter, 0.9);
  EXPECT_LT(std::sqrt(sigma2) / scatter, 2.5);
}

TEST(SampleError, AConstantRelativeErrorIsExactFromAnySampleAndOneViewHasNoSigma) {
  const ErrorSample g(3, 20, 16, 9, glint_guide(16));
  std::vector<Vec3> truth, values;
  for (int k = 0; k < g.view_count(); ++k)
    for (int t : g.texels(k)) {
      truth.push_back(glint_truth(g.normal(k, t)));
      values.push_back(1.1 * truth.back());
    }
  const ErrorEstimate e = sample_error(g, values, truth);
  EXPECT_NEAR(e.value, 0.1, 1e-12);
  EXPECT_NEAR(e.sigma, 0.0, 1e-12);
  EXPECT_THROW(sample_error(g, values, {Vec3(1, 1, 1)}), std::invalid_argument);
  const ErrorSample one(1, 10, 16, 2);
  const std::vector<Vec3> ones(10, Vec3(1, 1, 1)), off(10, Vec3(1.2, 1.2, 1.2));
  EXPECT_NEAR(sample_error(one, off, ones).value, 0.2, 1e-12);
  EXPECT_EQ(sample_error(one, off, ones).sigma, 0.0);
  // A black truth: 0 when the values are black too, +Inf (with an infinite sigma) when they are not.
  const std::vector<Vec3> black(10, Vec3(0, 0, 0));
  EXPECT_EQ(sample_error(one, black, black).value, 0.0);
  EXPECT_TRUE(std::isinf(sample_error(one, off, black).value));
  std::vector<Vec3> black_g(truth.size(), Vec3(0, 0, 0));
  const ErrorEstimate inf = sample_error(g, values, black_g);
  EXPECT_TRUE(std::isinf(inf.value));
  EXPECT_FALSE(std::isnan(inf.sigma));
}

}  // namespace
}  // namespace rsibr
