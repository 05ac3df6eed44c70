#include "compare/map_compare.h"

#include "compare/comparison_report.h"

#include "core/sphere_map.h"

#include <gtest/gtest.h>

#include <cmath>

namespace rsibr {
namespace {

// A map set over the octahedron's six views whose texel p of view v holds a smooth function of the
// world normal (the same radiance for the same normal, like a Lambertian ball).
MapSet normal_set(int size, double scale = 1.0, double roll = 0.0) {
  MapSet set;
  const ViewSet views = ViewSet::octahedron();
  for (const Vec3& v : views.views()) {
    MapView mv;
    mv.view = v;
    mv.world_from_view = world_from_view_for(v) * Eigen::AngleAxisd(roll, Vec3::UnitZ()).toRotationMatrix();
    mv.rgb = cv::Mat(size, size, CV_32FC3, cv::Scalar(0, 0, 0));
    for (int r = 0; r < size; ++r)
      for (int c = 0; c < size; ++c) {
        const Vec2 xy = sphere_map::disc_from_pixel(Vec2(c, r), size, size);
        if (xy.squaredNorm() >= 1) continue;
        const Vec3 n = mv.world_from_view * sphere_map::g_normal(xy);
        mv.rgb.at<cv::Vec3f>(r, c) =
            cv::Vec3f(float(scale * (1.2 + n.x())), float(scale * (1.5 + n.y())), float(scale * (1.1 + n.z())));
      }
    set.views.push_back(mv);
  }
  return set;
}

TEST(MapCompare, IdenticalSetsGiveZeroErrorAndTheCappedPsnr) {
  const MapSet a = normal_set(16);
  const Comparison c = compare_map_sets(a, a, CompareOptions{});
  ASSERT_EQ(c.pairs.size(), 6u);
  for (const ErrorMetrics* m : {&c.before, &c.after, &c.pairs[3].before, &c.pairs[3].after}) {
    EXPECT_EQ(m->relative_rms, 0.0);
    EXPECT_EQ(m->log_rms_stops, 0.0);
    EXPECT_DOUBLE_EQ(m->psnr_db, kPsnrCapDb);
  }
  ASSERT_TRUE(c.fit.has_value());
  for (double g : c.fit->gains) EXPECT_NEAR(g, 1.0, 1e-9);
}

TEST(MapCompare, TheFitSeparatesAnExposureAndWhiteBalanceOffset) {
  MapSet a = normal_set(16);
  const MapSet b = normal_set(16);
  for (MapView& v : a.views) v.rgb = apply_gains(v.rgb, {0.5, 0.25, 0.4});  // A underexposed, tinted
  const Comparison c = compare_map_sets(a, b, CompareOptions{});
  EXPECT_GT(c.before.relative_rms, 0.5);
  EXPECT_GT(c.before.log_rms_stops, 1.0);
  EXPECT_NEAR(c.fit->gains[0], 2.0, 1e-5);
  EXPECT_NEAR(c.fit->gains[1], 4.0, 1e-5);
  EXPECT_NEAR(c.fit->gains[2], 2.5, 1e-5);
  EXPECT_LT(c.after.relative_rms, 1e-5);
  EXPECT_LT(c.after.log_rms_stops, 1e-5);
}

TEST(MapCompare, ZeroConfidenceTexelsAreExcluded) {
  MapSet a = normal_set(8);
  const MapSet b = normal_set(8);
  // Garbage (including NaN) wherever A's confidence is zero: the left half of every view.
  for (MapView& v : a.views) {
    v.source = MapSource::Captured;
    v.confidence = cv::Mat(8, 8, CV_32FC1, cv::Scalar(1));
    for (int r = 0; r < 8; ++r)
      for (int c = 0; c < 4; ++c) {
        v.confidence.at<float>(r, c) = 0;
        v.rgb.at<cv::Vec3f>(r, c) = cv::Vec3f(1e6f, NAN, -3);
      }
  }
  const Comparison c = compare_map_sets(a, b, CompareOptions{});
  EXPECT_EQ(c.before.relative_rms, 0.0);
  // The disc is symmetric about its vertical axis: exactly half of its texels remain.
  const long disc = cv::countNonZero(sphere_map_weight(8, 8));
  EXPECT_EQ(c.pairs[0].before.texels, disc / 2);
}

TEST(MapCompare, AOneViewSetIsComparedWithItsMatchingView) {
  const MapSet full = normal_set(8);
  MapSet one;
  one.views.push_back(full.views[4]);
  one.views[0].rgb = apply_gains(one.views[0].rgb, {1.1, 1.1, 1.1});
  for (const Comparison& c :
       {compare_map_sets(one, full, CompareOptions{}), compare_map_sets(full, one, CompareOptions{})}) {
    ASSERT_EQ(c.pairs.size(), 1u);
    EXPECT_EQ(c.pairs[0].index_a + c.pairs[0].index_b, 4);
    EXPECT_GT(c.before.relative_rms, 0.05);
  }
}

TEST(MapCompare, MismatchedInputsAreErrorsThatNameTheInput) {
  CompareOptions o;
  o.name_a = "captured.exr";
  o.name_b = "computed.exr";
  const MapSet a = normal_set(8);
  auto expect_error = [&](const MapSet& x, const MapSet& y, const std::string& needle) {
    try {
      compare_map_sets(x, y, o);
      ADD_FAILURE() << "no error, expected " << needle;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  };
  expect_error(a, normal_set(16), "sizes must match");
  MapSet moved = normal_set(8);
  moved.views[2].view = Vec3(1, 0.2, 0).normalized();
  moved.views[2].world_from_view = world_from_view_for(moved.views[2].view);
  expect_error(moved, a, "view.002");
  MapSet bad = normal_set(8);
  bad.views[5].rgb.at<cv::Vec3f>(4, 4)[1] = INFINITY;
  expect_error(bad, a, "non-finite value at texel (4, 4)");
  expect_error(a, bad, "computed.exr: view.005");
  MapSet zero = normal_set(8);
  for (MapView& v : zero.views) v.confidence = cv::Mat(8, 8, CV_32FC1, cv::Scalar(0));
  expect_error(zero, a, "non-zero weight");
  MapSet negative = normal_set(8);
  negative.views[0].confidence = cv::Mat(8, 8, CV_32FC1, cv::Scalar(-1));
  expect_error(negative, a, "confidence");
}

TEST(MapCompare, LogEpsilonFollowsTheReferencesMedianNotASun) {
  const MapSet a = normal_set(16);
  MapSet sunny = normal_set(16);
  for (MapView& v : sunny.views) v.rgb.at<cv::Vec3f>(8, 8) *= 1e6f;  // one texel per view
  CompareOptions o;
  o.fit = false;
  const Comparison plain = compare_map_sets(a, a, o), sun = compare_map_sets(a, sunny, o);
  EXPECT_NEAR(sun.settings.log_epsilon / plain.settings.log_epsilon, 1.0, 0.02);
  EXPECT_GT(sun.settings.psnr_peak, 1e5);  // the PSNR's peak is the largest value, stated
  EXPECT_GT(plain.settings.log_epsilon, 0.0);
}

// Float extremes (the largest float, denormals, zeros, a huge gain) give finite metrics and gains.
TEST(MapCompare, ExtremeValuesGiveFiniteMetrics) {
  MapSet a = normal_set(8), b = normal_set(8);
  for (MapView& v : a.views) {
    v.rgb.at<cv::Vec3f>(3, 3) = cv::Vec3f(3.4e38f, 1e-44f, 0.f);
    v.rgb.at<cv::Vec3f>(4, 4) = cv::Vec3f(0, 0, 0);
    v.rgb *= 1e-30;  // A is 2^-100 times darker: the fitted gain is huge
    v.rgb.at<cv::Vec3f>(3, 4) = cv::Vec3f(3.4e38f, 3.4e38f, 3.4e38f);
  }
  for (MapView& v : b.views) {
    v.rgb.at<cv::Vec3f>(5, 5) = cv::Vec3f(3.4e38f, 0.f, 1e-44f);
    v.rgb.at<cv::Vec3f>(2, 5) = cv::Vec3f(3.4e38f, 3.4e38f, 3.4e38f);  // a float sum would overflow
    v.confidence = cv::Mat(8, 8, CV_32FC1, cv::Scalar(1));
    v.confidence.at<float>(2, 5) = 3.f;  // and so would weight times value in float
  }
  const Comparison c = compare_map_sets(a, b, CompareOptions{});
  for (const ErrorMetrics* m : {&c.before, &c.after, &c.pairs[2].before, &c.pairs[2].after}) {
    EXPECT_TRUE(std::isfinite(m->relative_rms));
    EXPECT_TRUE(std::isfinite(m->log_rms_stops));
    EXPECT_TRUE(std::isfinite(m->psnr_db));
    EXPECT_TRUE(std::isfinite(m->mse));
  }
  for (double g : c.fit->gains) {
    EXPECT_TRUE(std::isfinite(g));
    EXPECT_NEAR(std::log10(g), 30, 0.1);  // the outlier texels do not move it
  }
}

// B black but for a few texels at the float maximum (its median is 0, so eps comes from its mean,
// which must be summed in double): finite metrics.
TEST(MapCompare, AMostlyBlackReferenceWithHugeTexelsGivesFiniteMetrics) {
  MapSet a = normal_set(8), b = normal_set(8);
  for (MapView& v : b.views) {
    v.rgb.setTo(cv::Scalar(0, 0, 0));
    v.rgb.at<cv::Vec3f>(3, 3) = cv::Vec3f(3.4e38f, 3.4e38f, 3.4e38f);
    v.confidence = cv::Mat(8, 8, CV_32FC1, cv::Scalar(1));
    v.confidence.at<float>(3, 3) = 4.f;
  }
  const Comparison c = compare_map_sets(a, b, CompareOptions{});
  EXPECT_TRUE(std::isfinite(c.settings.log_epsilon) && c.settings.log_epsilon > 0);
  for (const ErrorMetrics* m : {&c.before, &c.after}) {
    EXPECT_TRUE(std::isfinite(m->relative_rms));
    EXPECT_TRUE(std::isfinite(m->log_rms_stops));
    EXPECT_TRUE(std::isfinite(m->psnr_db));
  }
}

// A captured set whose frames are rolled about the views (the camera's roll) against the computed
// one: the same radiance per normal, stored rotated. Compared texel by texel it would be far off;
// resampled into A's frame only the bilinear error of a smooth function remains.
TEST(MapCompare, RolledFramesAreResampledIntoAsFrame) {
  const MapSet a = normal_set(64), rolled = normal_set(64, 1.0, 0.7);
  const Comparison c = compare_map_sets(a, rolled, CompareOptions{});
  for (const PairComparison& p : c.pairs) {
    EXPECT_TRUE(p.b_resampled);
    EXPECT_NEAR(p.frame_angle_deg, 0.7 * 180 / kPi, 1e-6);
    EXPECT_LT(p.before.relative_rms, 2e-3) << p.name;
    EXPECT_GT(p.before.texels, 0.9 * double(cv::countNonZero(sphere_map_weight(64, 64))));
  }
  // Stored frames compared texel by texel would disagree by far more.
  ErrorSettings s;
  const cv::Mat w = sphere_map_weight(64, 64);
  EXPECT_GT(error_metrics(error_sums(a.views[0].rgb, rolled.views[0].rgb, w, s), s).relative_rms, 0.05);
  const Comparison same = compare_map_sets(a, a, CompareOptions{});
  EXPECT_FALSE(same.pairs[0].b_resampled);
}

TEST(MapCompare, EnvironmentsAreWeightedBySolidAngle) {
  EnvMap a = EnvMap::zeros(Layout::with_size(LayoutKind::LatLong, 32));
  a.pixels.setTo(cv::Scalar(1, 1, 1));
  EnvMap b = a;
  b.pixels = a.pixels.clone();
  // Double B in the top row (near the pole, tiny solid angle): the error is the row's share of the sphere.
  b.pixels.row(0).setTo(cv::Scalar(2, 2, 2));
  CompareOptions o;
  o.fit = false;
  const Comparison c = compare_environments(a, b, o);
  const cv::Mat sa = texel_solid_angles(a.layout);
  const double row = cv::sum(sa.row(0))[0], total = cv::sum(sa)[0];
  // relative RMS^2 = row * 1 / (row * 4 + (total - row) * 1)
  EXPECT_NEAR(c.before.relative_rms, std::sqrt(row / (4 * row + total - row)), 1e-6);
  EnvMap cube = EnvMap::zeros(Layout::with_size(LayoutKind::Cube, 8));
  EXPECT_THROW(compare_environments(a, cube, CompareOptions{}), std::invalid_argument);
}

TEST(ComparisonReport, TheJsonHoldsEachPairsMetricsAndThePicturesShareOneScale) {
  MapSet a = normal_set(16);
  const MapSet b = normal_set(16);
  for (MapView& v : a.views) v.rgb *= 2.0;  // one exposure off: the fit takes it out
  const Comparison c = compare_map_sets(a, b, CompareOptions{});
  const ComparisonImages auto_images = comparison_images(c);
  EXPECT_GT(auto_images.heat_max, 0);
  EXPECT_TRUE(std::isfinite(auto_images.exposure_stops));
  const ComparisonImages images = comparison_images(c, 0.5, 1.25f);
  EXPECT_EQ(images.heat_max, 0.5);
  EXPECT_EQ(images.exposure_stops, 1.25f);
  ASSERT_EQ(images.errors.size(), c.pairs.size());
  // A after the fit is B here, so every error is ~0 where there is weight.
  for (std::size_t i = 0; i < c.pairs.size(); ++i) {
    double worst = 0;
    cv::minMaxLoc(images.errors[i], nullptr, &worst, nullptr, nullptr, c.pairs[i].images.weight > 0);
    EXPECT_LT(worst, 1e-3) << i;
  }
  const nlohmann::json j = comparison_json(c, images, true);
  EXPECT_EQ(j["overall"]["before"]["relative_rms"].get<double>(), c.before.relative_rms);
  EXPECT_NEAR(j["fit"]["exposure_stops"].get<double>(), -1.0, 1e-6);
  EXPECT_EQ(j["heat_map"]["max"].get<double>(), 0.5);
  ASSERT_EQ(j["views"].size(), c.pairs.size());
  for (std::size_t i = 0; i < c.pairs.size(); ++i) {
    EXPECT_EQ(j["views"][i]["name"], c.pairs[i].name);
    EXPECT_EQ(j["views"][i]["after"]["log_rms_stops"].get<double>(), c.pairs[i].after.log_rms_stops);
    EXPECT_TRUE(j["views"][i].contains("view"));
  }
  EXPECT_FALSE(comparison_json(c, images, false)["views"][0].contains("view"));
  const cv::Mat panel = comparison_panel(c, images, 0, "title", "A x gains", "B");
  EXPECT_EQ(panel.type(), CV_8UC3);
  EXPECT_GT(panel.cols, 3 * 192);
}

}  // namespace
}  // namespace rsibr
