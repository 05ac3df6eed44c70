// calib/orientation/rotation_search.h: panoramas built from a known pattern of directions, turned by a known
// rotation and changed in exposure, are found again; the panorama's texel <-> direction maps are
// inverse; mismatched pyramids are a clear error.
#include "calib/orientation/rotation_search.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>

namespace rsibr {
namespace {

// A panorama of log luminance f(d) at every level (finest 128 wide), seen over the directions
// `seen` accepts.
ReflectionPanorama pattern_panorama(const std::function<double(const Vec3&)>& f,
                                    const std::function<bool(const Vec3&)>& seen) {
  ReflectionPanorama p;
  for (int w = 128; w >= 16; w /= 2) {
    PanoramaLevel l;
    l.width = w, l.height = w / 2;
    for (int v = 0; v < l.height; ++v)
      for (int u = 0; u < l.width; ++u) {
        const Vec3 d = panorama_direction(l, u, v);
        l.value.push_back(static_cast<float>(f(d)));
        l.weight.push_back(seen(d) ? 1.f : 0.f);
      }
    p.levels.push_back(l);
  }
  return p;
}

// A room-like world: a bright window, a lamp, a dark floor, a few soft blobs.
double room_pattern(const Vec3& d) {
  const Vec3 window = Vec3(0.8, -0.3, 0.5).normalized(), lamp = Vec3(-0.2, -0.95, 0.1).normalized();
  const Vec3 blob1 = Vec3(-0.7, 0.1, -0.7).normalized(), blob2 = Vec3(0.1, 0.2, -1).normalized();
  return 2 * std::exp(-std::pow(angle_between(d, window) / 0.3, 2)) +
         3 * std::exp(-std::pow(angle_between(d, lamp) / 0.15, 2)) + (d.y() > 0.3 ? -1.5 : 0) +
         std::exp(-std::pow(angle_between(d, blob1) / 0.25, 2)) +
         0.7 * std::exp(-std::pow(angle_between(d, blob2) / 0.2, 2));
}

double turn_between_deg(const Mat3& a, const Mat3& b) {
  return Eigen::AngleAxisd(a * b.transpose()).angle() * 180 / kPi;
}

TEST(RotationSearch, TexelAndDirectionMapsAreInverse) {
  PanoramaLevel l;
  l.width = 64, l.height = 32;
  for (double v : {0.0, 3.3, 15.5, 31.0})
    for (double u : {0.0, 7.25, 32.0, 63.0}) {
      const Vec2 t = panorama_texel(l, panorama_direction(l, u, v));
      EXPECT_NEAR(t.x(), u, 1e-9);
      EXPECT_NEAR(t.y(), v, 1e-9);
    }
  // phi = 0 is the camera's +z; the top row looks up the image (-y).
  EXPECT_GT(panorama_direction(l, 31.5, 15.5).z(), 0.99);
  EXPECT_LT(panorama_direction(l, 10, 0).y(), -0.99);
}

TEST(RotationSearch, AViewTurnedByAnyRotationAndExposedDifferentlyIsFoundWithinATexel) {
  // Each view sees all but a cone behind its ball and its own camera's reflection (as a chrome
  // ball does); view b's exposure is 8x (+log 8) and its contrast 1.2x (a different tone).
  auto sees = [](const Vec3& d) { return d.z() < std::cos(0.5) && d.z() > -std::cos(0.4); };
  const ReflectionPanorama a = pattern_panorama(room_pattern, sees);
  for (const Vec3& axis_angle : {Vec3(0, 1.6, 0), Vec3(0.3, 3.0, -0.2), Vec3(1.2, -0.4, 0.9), Vec3(0, 0, 0.05)}) {
    const Mat3 b_from_a = Eigen::AngleAxisd(axis_angle.norm(), axis_angle.normalized()).toRotationMatrix();
    // b sees direction e (its frame) where a sees b_from_a^T e.
    const ReflectionPanorama b = pattern_panorama(
        [&](const Vec3& e) { return 1.2 * room_pattern(b_from_a.transpose() * e) + std::log(8.0); }, sees);
    const RotationSearch r = search_rotation(a, b);
    EXPECT_LT(turn_between_deg(r.b_from_a, b_from_a), 360.0 / 128 / 2) << axis_angle.transpose();
    EXPECT_GT(r.score, 0.95);
    EXPECT_GT(r.overlap, 0.3);
    EXPECT_LE(r.runner_up, r.score);
  }
}

TEST(RotationSearch, PanoramasThatBarelyOverlapAreNotScoredAndMismatchedLevelsAreAnError) {
  // A view that sees only what lies well above it: no rotation gives an overlap larger than
  // what it sees, so none is scored.
  const ReflectionPanorama a = pattern_panorama(room_pattern, [](const Vec3& d) { return d.y() < -0.2; });
  RotationSearchOptions o;
  o.min_overlap = 0.6;  // more than either sees
  const RotationSearch r = search_rotation(a, a, o);
  EXPECT_EQ(r.score, -1);
  ReflectionPanorama shorter = a;
  shorter.levels.pop_back();
  EXPECT_THROW(search_rotation(a, shorter), std::invalid_argument);
}

}  // namespace
}  // namespace rsibr
