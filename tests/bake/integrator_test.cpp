// Properties of the lighting integrators (bake/integrator.h): white furnace, convergence to the
// reference quadrature, a 1e5 sun, determinism, SH against the reference, finiteness at the rim.
// Sizes are small (64 x 32 environments, 16^2..32^2 maps) so the suite stays fast.
#include "tests/bake/brdf_cases.h"
#include "tests/bake/integrator_cases.h"

#include "bake/integrator.h"
#include "bake/brdf_spec.h"
#include "bake/lambert.h"
#include "bake/sh_integrator.h"
#include "core/vec.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <vector>

namespace rsibr::test {
namespace {

const Vec3 kView = Vec3(0.3, 0.5, 0.81).normalized();

std::shared_ptr<const Brdf> lambert() { return std::make_shared<LambertBrdf>(Vec3(0.5, 0.6, 0.7)); }

cv::Mat bake(const Integrator& in, const Brdf& b, int size, int samples, std::uint64_t seed = 1,
             const Vec3& view = kView) {
  IntegratorOptions o;
  o.samples = samples;
  o.seed = seed;
  return in.radiance_map(b, view, world_from_view_for(view), size, o);
}

// The directional albedo of every texel of a size x size map (0 where the map is 0 by contract).
cv::Mat albedo_map(const Brdf& b, int size, const Vec3& view) {
  cv::Mat out(size, size, CV_64FC3, cv::Scalar::all(0));
  const Mat3 T = world_from_view_for(view);
  for (int r = 0; r < size; ++r)
    for (int c = 0; c < size; ++c)
      if (const auto t = integrator_detail::texel_frame(c, r, size, view, T)) {
        const Vec3 a = b.albedo(t->wo);
        out.at<cv::Vec3d>(r, c) = cv::Vec3d(a[0], a[1], a[2]);
      }
  return out;
}

// Largest |map - albedo| over all texels, and the mean signed relative error.
struct FurnaceError {
  double max_abs = 0, mean_rel = 0;
};
FurnaceError furnace_error(const cv::Mat& m, const cv::Mat& albedo) {
  FurnaceError e;
  double sum_map = 0, sum_alb = 0;
  for (int r = 0; r < m.rows; ++r)
    for (int c = 0; c < m.cols; ++c)
      for (int k = 0; k < 3; ++k) {
        const double v = m.at<cv::Vec3f>(r, c)[k], a = albedo.at<cv::Vec3d>(r, c)[k];
        e.max_abs = std::max(e.max_abs, std::abs(v - a));
        sum_map += v;
        sum_alb += a;
      }
  e.mean_rel = sum_map / sum_alb - 1;
  return e;
}

TEST(Integrators, WhiteFurnaceGivesAlbedoForEveryIntegrator) {
  const EnvMap white = latlong_env(patterns::constant(Vec3(1, 1, 1)), 128, 1);
  const std::vector<BrdfCase> brdfs = {{"lambert", lambert()}, {"ggx_a0.3", ggx(0.3)}, {"clearcoat", car_paint(0.2)}};
  const int size = 16;
  std::vector<std::unique_ptr<Integrator>> integrators;
  for (const char* method : {"reference", "mis", "fis", "sh"}) integrators.push_back(make_integrator(method, white));
  for (const auto& bc : brdfs) {
    const cv::Mat albedo = albedo_map(*bc.brdf, size, kView);
    for (const auto& in : integrators) {
      const std::string method = in->name();
      if (method == "sh" && bc.name != "lambert") continue;
      const cv::Mat m = bake(*in, *bc.brdf, size, 256);
      const FurnaceError e = furnace_error(m, albedo);
      std::printf("furnace %-9s %-9s max |err| %.2e  mean rel %+.2e\n", method.c_str(), bc.name.c_str(), e.max_abs,
                  e.mean_rel);
      const std::string what = method + " " + bc.name;
      if (method == "reference") {
        EXPECT_LT(e.max_abs, 1e-3) << what;
      } else if (method == "sh") {
        // Exactly rho up to the midpoint quadrature of the projection (l > 0 coefficients of a
        // constant are ~1e-5, not 0, on a 128 x 64 lat-long grid).
        EXPECT_LT(e.max_abs, 1e-4) << what;
      } else {
        // 256 samples: per-texel errors are statistical (mis, stratified: measured max 4.1e-3
        // over 3 x 200 texels) or quadrature (fis, Hammersley: 4.1e-3); the map mean averages
        // them out (measured |mean rel| <= 1.7e-4 mis, 2.3e-3 fis).
        EXPECT_LT(e.max_abs, 0.02) << what;
        EXPECT_LT(std::abs(e.mean_rel), 5e-3) << what;
      }
    }
  }
}

TEST(Integrators, IntegratorsConvergeToTheReference) {
  const EnvMap env = latlong_env(smooth_radiance(), 64);
  const int size = 16;
  const auto ref_in = make_integrator("reference", env);
  for (const BrdfCase& bc : std::vector<BrdfCase>{{"lambert", lambert()}, {"ggx_a0.3", ggx(0.3)}}) {
    const cv::Mat ref = bake(*ref_in, *bc.brdf, size, 0);
    for (const char* method : {"mis", "fis"}) {
      const auto in = make_integrator(method, env);
      std::vector<double> err;
      for (int n : {16, 64, 256}) {
        err.push_back(relative_rms(bake(*in, *bc.brdf, size, n, 3), ref));
        std::printf("converge %-4s %-9s N=%4d rel RMS %.3e\n", method, bc.name.c_str(), n, err.back());
      }
      const std::string what = std::string(method) + " " + bc.name;
      EXPECT_LT(err[1], err[0]) << what;
      EXPECT_LT(err[2], err[1]) << what;
      // Monte Carlo: 16x the samples gives at least ~4x lower RMS (stratified mis: measured 11x,
      // down to the reference's own quadrature floor; fis: 7.5x); demand 2.5x.
      EXPECT_LT(err[2], err[0] / 2.5) << what;
      // Measured at N = 256: mis 2.4e-3..2.6e-3, fis 1.4e-2..1.5e-2.
      EXPECT_LT(err[2], std::string(method) == "mis" ? 0.01 : 0.03) << what;
    }
  }
}

// Largest ratio of a texel to the median of its 8 neighbours (texels inside the disc only).
double max_neighbour_ratio(const cv::Mat& m) {
  double worst = 0;
  for (int r = 1; r + 1 < m.rows; ++r)
    for (int c = 1; c + 1 < m.cols; ++c) {
      std::vector<double> nb;
      bool ok = true;
      for (int dr = -1; dr <= 1; ++dr)
        for (int dc = -1; dc <= 1; ++dc) {
          const cv::Vec3f v = m.at<cv::Vec3f>(r + dr, c + dc);
          const double s = v[0] + v[1] + v[2];
          if (!(s > 0)) ok = false;
          if (dr || dc) nb.push_back(s);
        }
      if (!ok) continue;
      std::nth_element(nb.begin(), nb.begin() + 4, nb.end());
      const cv::Vec3f v = m.at<cv::Vec3f>(r, c);
      worst = std::max(worst, (v[0] + v[1] + v[2]) / nb[4]);
    }
  return worst;
}

TEST(Integrators, SunIsNeitherLostNorFirefly) {
  const EnvMap env = latlong_env(sunny_radiance(1e5), 64, 8);
  const int size = 24;
  const auto ref_in = make_integrator("reference", env);
  const auto mis = make_integrator("mis", env);
  // The view looks toward the sun's side so the sun lights most of the map.
  const Vec3 view = Vec3(0.3, 0.6, -0.5).normalized();
  for (const BrdfCase& bc : std::vector<BrdfCase>{{"lambert", lambert()}, {"ggx_a0.3", ggx(0.3)}}) {
    const cv::Mat ref = bake(*ref_in, *bc.brdf, size, 0, 1, view);
    const cv::Mat m = bake(*mis, *bc.brdf, size, 32, 1, view);
    const double mean_ratio = map_mean(m) / map_mean(ref);
    const double ratio_ref = max_neighbour_ratio(ref), ratio_mis = max_neighbour_ratio(m);
    std::printf("sun %-9s mean mis/ref %.4f  rel RMS %.3e  max neighbour ratio: ref %.2f mis %.2f\n", bc.name.c_str(),
                mean_ratio, relative_rms(m, ref), ratio_ref, ratio_mis);
    EXPECT_NEAR(mean_ratio, 1.0, 0.02) << bc.name;  // measured 0.999
    EXPECT_LT(ratio_mis, 1.5 * ratio_ref + 0.5) << bc.name;
    EXPECT_LT(relative_rms(m, ref), 0.05) << bc.name;  // measured 0.021 at 32 samples
  }
}

TEST(Integrators, SameSeedSameBytes) {
  const EnvMap env = latlong_env(sunny_radiance(), 64, 8);
  const auto b = ggx(0.3);
  for (const char* method : {"mis", "fis"}) {
    const auto in = make_integrator(method, env);
    const cv::Mat a = bake(*in, *b, 16, 8, 42), a2 = bake(*in, *b, 16, 8, 42), c = bake(*in, *b, 16, 8, 43);
    EXPECT_EQ(0, std::memcmp(a.data, a2.data, a.total() * a.elemSize())) << method;
    EXPECT_NE(0, std::memcmp(a.data, c.data, a.total() * a.elemSize())) << method;
  }
}

TEST(Integrators, ResultIsIndependentOfThreadCount) {
  const EnvMap env = latlong_env(sunny_radiance(), 64, 8);
  const auto b = ggx(0.3);
  for (const char* method : {"reference", "mis", "fis"}) {
    const auto in = make_integrator(method, env);
    cv::Mat one, two;
    {
      tbb::global_control g(tbb::global_control::max_allowed_parallelism, 1);
      one = bake(*in, *b, 16, 8, 42);
    }
    {
      tbb::global_control g(tbb::global_control::max_allowed_parallelism, 2);
      two = bake(*in, *b, 16, 8, 42);
    }
    EXPECT_EQ(0, std::memcmp(one.data, two.data, one.total() * one.elemSize())) << method;
  }
}

TEST(Integrators, ShMatchesReferenceForLambert) {
  const auto b = lambert();
  const int size = 24;
  {
    const EnvMap env = latlong_env(smooth_radiance(), 64);
    const cv::Mat ref = bake(*make_integrator("reference", env), *b, size, 0);
    const double e = relative_rms(bake(*make_integrator("sh", env), *b, size, 0), ref);
    std::printf("sh vs reference, smooth env: rel RMS %.3e\n", e);
    EXPECT_LT(e, 0.02);
  }
  {
    // Order 2 cannot hold a sun's sharp shadow line: the error is measured and documented,
    // bounded loosely so a regression (e.g. wrong A_l) still fails.
    const EnvMap env = latlong_env(sunny_radiance(1e5), 64, 8);
    const cv::Mat ref = bake(*make_integrator("reference", env), *b, size, 0);
    const double e = relative_rms(bake(*make_integrator("sh", env), *b, size, 0), ref);
    std::printf("sh vs reference, 1e5 sun: rel RMS %.3e\n", e);
    EXPECT_LT(e, 0.25);
  }
  EXPECT_THROW(make_integrator("sh", latlong_env(smooth_radiance(), 16))
                   ->radiance_map(*ggx(0.3), kView, world_from_view_for(kView), 8, IntegratorOptions{}),
               std::invalid_argument);
}

TEST(Integrators, NoNaNAtTheRim) {
  const EnvMap env = latlong_env(sunny_radiance(), 64, 8);
  const std::vector<BrdfCase> brdfs = {
      {"lambert", lambert()}, {"ggx_a0.01", ggx(0.01)}, {"clearcoat", car_paint(0.01)}};
  for (const char* method : {"reference", "mis", "fis", "sh"}) {
    const auto in = make_integrator(method, env);
    for (const auto& bc : brdfs) {
      if (std::string(method) == "sh" && bc.name != "lambert") continue;
      for (const Vec3& view : {Vec3(0, 0, 1), Vec3(0, 1, 0), Vec3(0, -1, 0), kView}) {
        const cv::Mat m = bake(*in, *bc.brdf, 33, 4, 1, view);
        EXPECT_TRUE(all_finite_nonnegative(m)) << method << " " << bc.name;
        // Texels outside the disc are exactly 0.
        EXPECT_EQ(m.at<cv::Vec3f>(0, 0), cv::Vec3f(0, 0, 0));
      }
    }
  }
}

// Not a test: the measured error-versus-samples table of the report (run with
// --gtest_also_run_disabled_tests --gtest_filter='*Measure*'). Timing is printed, never asserted.
TEST(Integrators, DISABLED_MeasureErrorVersusSamples) {
  const int size = 64;
  for (const char* env_name : {"smooth", "sun1e5"}) {
    const EnvMap env = std::string(env_name) == "smooth" ? latlong_env(smooth_radiance(), 128)
                                                         : latlong_env(sunny_radiance(1e5), 128, 8);
    const Vec3 view = Vec3(0.3, 0.6, -0.5).normalized();
    for (const BrdfCase& bc : std::vector<BrdfCase>{{"lambert", lambert()}, {"ggx_a0.2", ggx(0.2)}}) {
      auto timed = [&](const Integrator& in, int n) {
        const auto t0 = std::chrono::steady_clock::now();
        cv::Mat m = bake(in, *bc.brdf, size, n, 1, view);
        return std::make_pair(m, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
      };
      const auto [ref, t_ref] = timed(*make_integrator("reference", env), 0);
      std::printf("%s %s %dx%d map: reference %.3f s\n", env_name, bc.name.c_str(), size, size, t_ref);
      std::vector<const char*> methods = {"mis", "fis"};
      if (bc.name == "lambert") methods.push_back("sh");
      for (const char* method : methods) {
        const auto in = make_integrator(method, env);
        for (int n : {16, 64, 256, 1024}) {
          const auto [m, t] = timed(*in, n);
          std::printf("  %-3s N=%4d rel RMS %.3e  %.3f s\n", method, n, relative_rms(m, ref), t);
          if (std::string(method) == "sh") break;
        }
      }
    }
  }
}

}  // namespace
}  // namespace rsibr::test

namespace rsibr {
namespace {

// The texel mask (error estimates on a subset) changes which texels are computed, never their values.
TEST(Integrators, MaskedTexelsEqualTheFullMap) {
  const EnvMap env = test::latlong_env(test::sunny_radiance(), 64, 8);
  const auto glossy = parse_brdf("{type: ggx, roughness: 0.3, fresnel: {type: schlick, f0: [0.9, 0.6, 0.3]}}");
  const auto diffuse = parse_brdf("{type: lambert, albedo: [0.5, 0.6, 0.7]}");
  const int size = 24;
  cv::Mat mask(size, size, CV_8UC1, cv::Scalar(0));
  for (int i = 0; i < size * size; i += 7) mask.at<unsigned char>(i / size, i % size) = 1;
  const Vec3 view = Vec3(0.2, 0.5, 0.8).normalized();
  const Mat3 T = world_from_view_for(view);
  for (const char* method : {"reference", "mis", "fis", "sh"}) {
    const Brdf& b = std::string(method) == "sh" ? *diffuse : *glossy;
    const auto in = make_integrator(method, env);
    IntegratorOptions o;
    o.samples = 8;
    o.seed = 5;
    const cv::Mat full = in->radiance_map(b, view, T, size, o);
    o.texel_mask = mask;
    const cv::Mat part = in->radiance_map(b, view, T, size, o);
    int compared = 0;
    for (int r = 0; r < size; ++r)
      for (int c = 0; c < size; ++c) {
        const cv::Vec3f p = part.at<cv::Vec3f>(r, c), f = full.at<cv::Vec3f>(r, c);
        if (mask.at<unsigned char>(r, c)) {
          EXPECT_EQ(p, f) << method << " " << r << "," << c;
          compared += f != cv::Vec3f(0, 0, 0);
        } else {
          EXPECT_EQ(p, cv::Vec3f(0, 0, 0)) << method;
        }
      }
    EXPECT_GT(compared, 40) << method;
  }
}

}  // namespace
}  // namespace rsibr
