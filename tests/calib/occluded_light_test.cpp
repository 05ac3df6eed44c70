// The light an occluder takes from a grey ball, restored (calib/extraction/occluded_light.h): analytic caps
// under a uniform environment, occluders as bright as what they hide, unseen and hidden light.
#include "calib/extraction/occluded_light.h"

#include "core/sphere_map.h"

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

// A 64 x 64 chrome map (no Fresnel, world = view frame) rendered from its centre `c`: each texel
// shows the probe in its mirror direction, or `head_radiance` where that ray meets the sphere
// (head_centre, head_radius).
MapView rendered_chrome(const EnvMap& probe, const Vec3& c, const Vec3& head_centre, double head_radius,
                        float head_radiance) {
  MapView mv;
  mv.rgb = cv::Mat(64, 64, CV_32FC3, cv::Scalar::all(0));
  Occluder head;
  head.centre = head_centre;
  head.radius = head_radius;
  for (int r = 0; r < 64; ++r)
    for (int col = 0; col < 64; ++col) {
      const Vec2 xy = sphere_map::disc_from_pixel(Vec2(col, r), 64, 64);
      if (xy.squaredNorm() >= 1) continue;
      const Vec3 d = sphere_map::g_mirror(xy);
      float v[3];
      sample_bilinear(probe, d, v);
      if (head_radius > 0 && ray_hits(head, c, d)) v[0] = v[1] = v[2] = head_radiance;
      mv.rgb.at<cv::Vec3f>(r, col) = cv::Vec3f(v[0], v[1], v[2]);
    }
  return mv;
}

// A photographer's capsule about a vertical axis through (5, 0, 30), 6 radii wide.
OccluderLight photographer_capsule() {
  OccluderLight o;
  o.shape.kind = Occluder::capsule;
  o.shape.centre = Vec3(5, -4, 30);
  o.shape.axis = Vec3(0, 1, 0);
  o.shape.length = 8;
  o.shape.radius = 6;
  o.source = OccluderLight::seen_by_chrome;
  return o;
}

TEST(OccludedLight, AHeadInFrontOfASunForTheChromeBallHidesNothingOfItFromTheGreyBall) {
  // A sun of 1000 within 3 degrees of +z. The chrome ball (centre (5, 0, 10)) sees a head of
  // radiance 0.1 at (5, 0, 30) right in front of it; the grey ball's texel facing +z (p = (0, 0,
  // 11)) sees the sun past the head, 14 degrees away. Its ray toward the sun meets the capsule
  // at (0, 0, 30), where the chrome ball sees the far environment: nothing of the sun is restored
  // (read along the ray's own direction, the chrome ball's head would hide the sun: a ratio of ~3.7).
  const Layout layout(LayoutKind::LatLong, 256, 128);
  EnvMap probe = EnvMap::zeros(layout);
  for (int y = 0; y < layout.height(); ++y)
    for (int x = 0; x < layout.width(); ++x) {
      const double v = layout.texel_direction(x, y)->z() > std::cos(3 * kPi / 180) ? 1000 : 1;
      probe.pixels.at<cv::Vec3f>(y, x) = cv::Vec3f(float(v), float(v), float(v));
    }
  const OpenLight light = open_light(probe, cv::Mat(128, 256, CV_32FC1, cv::Scalar(1)), nullptr, 128);
  const Vec3 chrome_centre(5, 0, 10);
  const MapView chrome = rendered_chrome(probe, chrome_centre, Vec3(5, 0, 30), 2, 0.1f);
  const OccludedLight r = occluded_light(grey_map(), Mat3::Identity(), grey_cone(), {photographer_capsule()}, light,
                                         &chrome, chrome_centre);
  EXPECT_GE(centre_ratio(r), 1.0f);
  EXPECT_LT(centre_ratio(r), 1.01f);
}

TEST(OccludedLight, AnEmptyCapsuleOnATexturedEnvironmentRestoresNothing) {
  // A checker of 0.2 and 5 (11 degree squares); the chrome ball sees it and nothing else. Its
  // texels differ from the probe's area means by up to 25x at the squares' edges, yet what the
  // capsule adds averages out.
  const Layout layout(LayoutKind::LatLong, 256, 128);
  EnvMap probe = EnvMap::zeros(layout);
  for (int y = 0; y < layout.height(); ++y)
    for (int x = 0; x < layout.width(); ++x) {
      const float v = ((x / 8 + y / 8) % 2) ? 5.0f : 0.2f;
      probe.pixels.at<cv::Vec3f>(y, x) = cv::Vec3f(v, v, v);
    }
  const OpenLight light = open_light(probe, cv::Mat(128, 256, CV_32FC1, cv::Scalar(1)), nullptr, 64);
  const Vec3 chrome_centre(5, 0, 10);
  const MapView chrome = rendered_chrome(probe, chrome_centre, Vec3::Zero(), 0, 0);
  const OccludedLight r = occluded_light(grey_map(), Mat3::Identity(), grey_cone(), {photographer_capsule()}, light,
                                         &chrome, chrome_centre);
  EXPECT_NEAR(centre_ratio(r), 1.0, 0.03);
  EXPECT_LT(r.mean_stops, 0.03);
}

TEST(OccludedLight, ABodyBrighterThanWhatItHidesDarkensTheMap) {
  // A photographer of radiance 2 (lit, before a uniform environment of 1), within the brightest a
  // diffuse body can be (4 E_max / pi = 4): E_scene = pi - pi / 4 + 2 pi / 4, a ratio of 1 / 1.25.
  const MapView chrome = uniform_chrome(2.0f);
  const OccludedLight r =
      occluded_light(grey_map(), Mat3::Identity(), grey_cone(), {ball_ahead(OccluderLight::seen_by_chrome)},
                     uniform_light(), &chrome, Vec3(5, 0, 10));
  EXPECT_NEAR(centre_ratio(r), 1 / 1.25, 0.01);
}

TEST(OccludedLight, ChromeTexelsBrighterThanAnyLitBodyShowLightNotABody) {
  // Texels of 1000 under an environment of 1: lamps, not a body (no diffuse surface lit by it
  // exceeds 4 E_max / pi = 4), so nothing is darkened (read as a body, the ratio would hit the
  // clamp, 1/2).
  const MapView chrome = uniform_chrome(1000.0f);
  const OccludedLight r =
      occluded_light(grey_map(), Mat3::Identity(), grey_cone(), {ball_ahead(OccluderLight::seen_by_chrome)},
                     uniform_light(), &chrome, Vec3(5, 0, 10));
  EXPECT_NEAR(centre_ratio(r), 1.0, 1e-6);
}

TEST(OccludedLight, ATexelTheModelDoesNotExplainGetsTheDifferenceNotTheRatio) {
  // The black ball ahead takes pi / 4 of the centre texel's pi. That texel holds 10x what the
  // rest of the map says the model gives it (sunlight the quadrature misses, as at a terminator):
  // the light taken is added in the map's scale, k pi / 4 with k ~ 1 / (0.9 pi), a ratio of about
  // 1.03; multiplied, it would be 4 / 3 of a bright texel.
  MapView g = grey_map();
  g.rgb.at<cv::Vec3f>(16, 16) = cv::Vec3f(10, 10, 10);
  const OccludedLight r =
      occluded_light(g, Mat3::Identity(), grey_cone(), {ball_ahead(OccluderLight::lambert_ball, 0.0)}, uniform_light(),
                     nullptr, Vec3::Zero());
  EXPECT_GT(centre_ratio(r), 1.0f);
  EXPECT_LT(centre_ratio(r), 1.05f);
  // Its neighbour, which the model explains, keeps the ratio of the irradiances (a little under 4 / 3).
  EXPECT_GT(r.ratio.at<cv::Vec3f>(16, 17)[1], 1.25f);
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
