// Occluders by geometry (calib/extraction/occluders.h): analytic rays against spheres and capsules, and the
// rig's occluders as a chrome ball's view sees them.
#include "calib/extraction/occluders.h"

#include <gtest/gtest.h>

#include <cmath>

namespace rsibr {
namespace {

TEST(Occluders, ARayMeetsASphereExactlyWhenItPassesWithinItsRadius) {
  Occluder s;
  s.kind = Occluder::sphere;
  s.centre = Vec3(0, 0, 10);
  s.radius = 1;
  EXPECT_TRUE(ray_hits(s, Vec3::Zero(), Vec3(0, 0, 1)));
  EXPECT_TRUE(ray_hits(s, Vec3::Zero(), Vec3(0.099, 0, 1).normalized()));   // passes 0.99 from the centre
  EXPECT_FALSE(ray_hits(s, Vec3::Zero(), Vec3(0.101, 0, 1).normalized()));  // passes 1.005 from it
  EXPECT_FALSE(ray_hits(s, Vec3::Zero(), Vec3(0, 0, -1)));                  // behind the ray's start
  EXPECT_FALSE(ray_hits(s, Vec3::Zero(), Vec3(0, 0, 1), 8.5));              // stops before it
  EXPECT_TRUE(ray_hits(s, Vec3::Zero(), Vec3(0, 0, 1), 9.5));
}

TEST(Occluders, ARayMeetsACapsuleWithinItsRadiusOfTheSegmentOnly) {
  Occluder c;
  c.kind = Occluder::capsule;
  c.centre = Vec3(0, 0, 5);  // a vertical segment from (0, 0, 5) down to (0, 4, 5) (camera y is down)
  c.axis = Vec3(0, 1, 0);
  c.length = 4;
  c.radius = 0.5;
  EXPECT_TRUE(ray_hits(c, Vec3::Zero(), Vec3(0, 0.4, 1).normalized()));     // meets the segment
  EXPECT_TRUE(ray_hits(c, Vec3::Zero(), Vec3(0.09, 0.2, 1).normalized()));  // passes 0.45 beside it
  EXPECT_FALSE(ray_hits(c, Vec3::Zero(), Vec3(0.11, 0.2, 1).normalized()));
  EXPECT_FALSE(ray_hits(c, Vec3::Zero(), Vec3(0, -0.2, 1).normalized()));  // above its top (1 from it)
  EXPECT_TRUE(ray_hits(c, Vec3::Zero(), Vec3(0, -0.09, 1).normalized()));  // within the top's cap
  EXPECT_FALSE(ray_hits(c, Vec3::Zero(), Vec3(0, 1.2, 1).normalized()));   // below its bottom
  // Parallel to the segment, beside it and along it.
  EXPECT_TRUE(ray_hits(c, Vec3(0.3, -1, 5), Vec3(0, 1, 0)));
  EXPECT_FALSE(ray_hits(c, Vec3(0.6, -1, 5), Vec3(0, 1, 0)));
}

// A chrome ball 10 radii ahead, a grey one beside it, world down = camera +y: the rays from the
// chrome ball's surface toward the grey ball, down its stand, and back past the camera toward the
// photographer are masked; a ray up and sideways is not.
TEST(Occluders, TheRigsOccludersCoverTheOtherBallTheStandsAndThePhotographer) {
  BallCone chrome{Vec3(0, 0, 1), std::asin(0.1)};  // centre at (0, 0, 10) in chrome radii
  OtherBall grey{"grey", {Vec3(3, 0, 10).normalized(), std::asin(1 / Vec3(3, 0, 10).norm())}, 1.0};
  const std::vector<Occluder> occ = chrome_occluders(chrome, {grey}, Vec3(0, 1, 0), 0.05);
  ASSERT_EQ(occ.size(), 4u);  // the grey ball, two stands, the photographer
  auto masked = [&](const Vec3& from, const Vec3& dir) {
    for (const Occluder& o : occ)
      if (ray_hits(o, from, dir.normalized())) return o.what;
    return std::string();
  };
  const Vec3 c(0, 0, 10);
  EXPECT_EQ(masked(c + Vec3(1, 0, 0), Vec3(1, 0, 0)), "ball grey");
  EXPECT_EQ(masked(c + Vec3(0, 1, 0), Vec3(0, 1, 0)), "stand under the chrome ball");
  EXPECT_EQ(masked(c + Vec3(0, 0, -1), Vec3(0, 0.15, -1)), "photographer");
  EXPECT_EQ(masked(c + Vec3(0, -1, 0), Vec3(-0.3, -1, 0.2)), "");
  // No down: the other balls only.
  EXPECT_EQ(chrome_occluders(chrome, {grey}, std::nullopt, 0.05).size(), 1u);
}

}  // namespace
}  // namespace rsibr
