// The light an occluder takes from a grey ball, restored (calib/occluded_light.h): analytic caps
// under a uniform environment, occluders as bright as what they hide, unseen and hidden light.
#include "calib/occluded_light.h"

#include <gtest/gtest.h>

#include <cmath>

namespace rsibr {
namespace {

// A uniform probe of radiance 1, seen everywhere except where `unseen` says.
template <class Unseen>
OpenLight uniform_light(Unseen unseen) {
  const Layout layout(LayoutKind::LatLong, 256, 128);
  EnvMap probe = EnvMap::zeros(layout);
  probe.pixels.setTo(cv::Scalar::all(1));
  cv::Mat weight(layout.height(), layout.width(), CV_32FC1, cv::Scalar(1));
  for (int y = 0; y < layout.height(); ++y)
    for (int x = 0; x < layout.width(); ++x)
      if (unseen(*layout.texel_direction(x, y))) weight.at<float>(y, x) = 0;
  return open_light(probe, weight, nullptr, 128);
}
OpenLight uniform_light() {
  return uniform_light([](const Vec3&) { return false; });
}

// A 33 x 33 grey map whose centre texel's normal is +z (view = camera = world frame), the ball's
// centre at (0, 0, 10): that texel's surface point is p = (0, 0, 11).
MapView grey_map() {
  MapView mv;
  mv.warp = CentralDirection::Normal;
  mv.rgb = cv::Mat(33, 33, CV_32FC3, cv::Scalar::all(1));
  mv.confidence = cv::Mat(33, 33, CV_32FC1, cv::Scalar(1));
  return mv;
}
BallCone grey_cone() {
  BallCone c;
  c.axis = Vec3(0, 0, 1);
  c.half_angle = std::asin(0.1);
  return c;
}
// A ball of radius 2 whose centre is 4 from p along +z: from p it covers a cap of half-angle 30
// degrees about the normal, whose cosine-weighted solid angle is pi sin^2(30) = pi / 4.
OccluderLight ball_ahead(OccluderLight::Source source, double albedo = 0) {
  OccluderLight o;
  o.shape.kind = Occluder::sphere;
  o.shape.centre = Vec3(0, 0, 15);
  o.shape.radius = 2;
  o.source = source;
  o.albedo = albedo;
  return o;
}
MapView uniform_chrome(float value) {
  MapView mv;
  mv.rgb = cv::Mat(64, 64, CV_32FC3, cv::Scalar::all(value));
  return mv;
}
double centre_ratio(const OccludedLight& r) { return r.ratio.at<cv::Vec3f>(16, 16)[1]; }

TEST(OccludedLight, ABlackBallRestoresTheAnalyticCapOfTheTexelFacingIt) {
  const OccludedLight r =
      occluded_light(grey_map(), Mat3::Identity(), grey_cone(), {ball_ahead(OccluderLight::lambert_ball, 0.0)},
                     uniform_light(), nullptr, Vec3::Zero());
  // E_open = pi, E_scene = pi - pi / 4.
  EXPECT_NEAR(centre_ratio(r), 4.0 / 3.0, 0.02 * 4.0 / 3.0);
  EXPECT_NEAR(r.max_stops, std::log2(4.0 / 3.0), 0.03);
  // Texels toward the rim face the ball less and lose less.
  EXPECT_LT(r.ratio.at<cv::Vec3f>(16, 1)[0], r.ratio.at<cv::Vec3f>(16, 8)[0]);
  EXPECT_LT(r.ratio.at<cv::Vec3f>(16, 8)[0], centre_ratio(r));
  EXPECT_GE(r.ratio.at<cv::Vec3f>(16, 1)[0], 1.0f);
}

TEST(OccludedLight, AnOccluderAsBrightAsWhatItHidesRestoresNothing) {
  // A mirror ball (no Fresnel) reflects the uniform environment: radiance 1.
  const OccludedLight mirror =
      occluded_light(grey_map(), Mat3::Identity(), grey_cone(), {ball_ahead(OccluderLight::mirror_ball)},
                     uniform_light(), nullptr, Vec3::Zero());
  // The photographer, as the chrome ball of the view sees it: radiance 1.
  const MapView chrome = uniform_chrome(1.0f);
  const OccludedLight seen =
      occluded_light(grey_map(), Mat3::Identity(), grey_cone(), {ball_ahead(OccluderLight::seen_by_chrome)},
                     uniform_light(), &chrome, Vec3(5, 0, 10));
  for (const OccludedLight* r : {&mirror, &seen}) {
    double worst = 0;
    for (int y = 0; y < 33; ++y)
      for (int x = 0; x < 33; ++x)
        for (int k = 0; k < 3; ++k) worst = std::max(worst, std::abs(r->ratio.at<cv::Vec3f>(y, x)[k] - 1.0));
    EXPECT_LT(worst, 1e-5);
  }
}

TEST(OccludedLight, ThePhotographersRadianceIsWhatTheChromeBallSees) {
  // Radiance 0.5 over the cap: E_scene = pi - 0.5 pi / 4.
  const MapView chrome = uniform_chrome(0.5f);
  const OccludedLight r =
      occluded_light(grey_map(), Mat3::Identity(), grey_cone(), {ball_ahead(OccluderLight::seen_by_chrome)},
                     uniform_light(), &chrome, Vec3(5, 0, 10));
  EXPECT_NEAR(centre_ratio(r), 1.0 / 0.875, 0.01);
  // Without the view's chrome map, or where another ball hides it, nothing is known to restore.
  const OccludedLight none =
      occluded_light(grey_map(), Mat3::Identity(), grey_cone(), {ball_ahead(OccluderLight::seen_by_chrome)},
                     uniform_light(), nullptr, Vec3(5, 0, 10));
  EXPECT_EQ(centre_ratio(none), 1.0f);
  const OccludedLight hidden =
      occluded_light(grey_map(), Mat3::Identity(), grey_cone(), {ball_ahead(OccluderLight::seen_by_chrome)},
                     uniform_light(), &chrome, Vec3(5, 0, 10), cv::Mat(64, 64, CV_8UC1, cv::Scalar(1)));
  EXPECT_EQ(centre_ratio(hidden), 1.0f);
}

TEST(OccludedLight, ChromeTexelsClippedInEveryBracketAreNotRead) {
  // A half-bright chrome map whose every texel is a lower bound: nothing is known to restore.
  MapView chrome = uniform_chrome(0.5f);
  chrome.clipped = cv::Mat(64, 64, CV_32FC1, cv::Scalar(1));
  const OccludedLight r =
      occluded_light(grey_map(), Mat3::Identity(), grey_cone(), {ball_ahead(OccluderLight::seen_by_chrome)},
                     uniform_light(), &chrome, Vec3(5, 0, 10));
  EXPECT_EQ(centre_ratio(r), 1.0f);
}

TEST(OccludedLight, ASunAGigaTimesBrighterAndANonFiniteTexelStayFinite) {
  // A uniform probe of 1 with a sun of 1e9 behind the black ball (+z) and a NaN texel elsewhere:
  // the NaN is not seen, the sun's hidden light is restored up to the clamp, everything finite.
  const Layout layout(LayoutKind::LatLong, 256, 128);
  EnvMap probe = EnvMap::zeros(layout);
  probe.pixels.setTo(cv::Scalar::all(1));
  const Vec2 sun = layout.pixel(Vec3(0, 0, 1)), nan = layout.pixel(Vec3(0, 0, -1));
  probe.pixels.at<cv::Vec3f>(int(sun.y()), int(sun.x())) = cv::Vec3f(1e9f, 1e9f, 1e9f);
  probe.pixels.at<cv::Vec3f>(int(nan.y()), int(nan.x())) = cv::Vec3f(NAN, NAN, NAN);
  const OpenLight light = open_light(probe, cv::Mat(128, 256, CV_32FC1, cv::Scalar(1)), nullptr, 64);
  EXPECT_TRUE(cv::checkRange(light.env.pixels));
  EXPECT_TRUE(cv::checkRange(light.irradiance.pixels));
  const OccludedLight r = occluded_light(grey_map(), Mat3::Identity(), grey_cone(),
                                         {ball_ahead(OccluderLight::lambert_ball, 0.0)}, light, nullptr, Vec3::Zero());
  EXPECT_TRUE(cv::checkRange(r.ratio));
  EXPECT_NEAR(centre_ratio(r), std::exp2(r.clamp_stops), 1e-5);
  EXPECT_TRUE(std::isfinite(r.mean_stops) && std::isfinite(r.max_stops));
}

TEST(OccludedLight, LightTheProbeDidNotSeeRestoresNothing) {
  const OpenLight light = uniform_light([](const Vec3& w) { return w.z() > 0.5; });
  const OccludedLight r = occluded_light(grey_map(), Mat3::Identity(), grey_cone(),
                                         {ball_ahead(OccluderLight::lambert_ball, 0.0)}, light, nullptr, Vec3::Zero());
  EXPECT_EQ(centre_ratio(r), 1.0f);
}

TEST(OccludedLight, RatiosAreClampedAndMultiplyTheMap) {
  // Facing a black ball that fills most of the hemisphere: the ratio stops at 2^clamp_stops.
  OccluderLight big = ball_ahead(OccluderLight::lambert_ball, 0.0);
  big.shape.centre = Vec3(0, 0, 11.5 + 20);
  big.shape.radius = 20;
  const OccludedLight r =
      occluded_light(grey_map(), Mat3::Identity(), grey_cone(), {big}, uniform_light(), nullptr, Vec3::Zero());
  EXPECT_NEAR(centre_ratio(r), std::exp2(r.clamp_stops), 1e-5);
  MapView g = grey_map();
  restore_occluded_light(g, r);
  EXPECT_NEAR(g.rgb.at<cv::Vec3f>(16, 16)[2], r.ratio.at<cv::Vec3f>(16, 16)[2], 1e-6);
  EXPECT_TRUE(cv::checkRange(g.rgb));
}

}  // namespace
}  // namespace rsibr
