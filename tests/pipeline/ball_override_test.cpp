// `process --ball VIEW:BALL=X,Y,R` (pipeline/ball_override.h): parsed strictly against the photo set.
#include "pipeline/ball_override.h"

#include <gtest/gtest.h>

namespace rsibr {
namespace {

PhotoSet set() {
  PhotoSet s;
  s.views = {{"north", {}}, {"south", {}}};
  s.balls = {{"chrome", BallKind::chrome, 0.1}, {"grey", BallKind::grey, 0.1}};
  return s;
}

TEST(BallOverride, AWellFormedOverrideNamesItsViewBallAndPlace) {
  const auto o = parse_ball_overrides({"north:grey=412.5,300,62", "south:chrome=10,20,30.5"}, set());
  ASSERT_EQ(o.size(), 2u);
  EXPECT_EQ(o[0].view, "north");
  EXPECT_EQ(o[0].ball, "grey");
  EXPECT_EQ(o[0].guess.centre_px, Vec2(412.5, 300));
  EXPECT_EQ(o[0].guess.radius_px, 62);
  EXPECT_EQ(find_override(o, "south", "chrome")->radius_px, 30.5);
  EXPECT_FALSE(find_override(o, "south", "grey"));
}

TEST(BallOverride, MalformedTextsUnknownNamesAndRepeatsAreOneLineErrors) {
  for (const char* bad : {"north:grey", "north=1,2,3", "north:grey=1,2", "north:grey=1,2,3,4", "north:grey=a,b,c",
                          "north:grey=1,2,0.5", "north:grey=1,2,nan", "west:grey=1,2,30", "north:glossy=1,2,30"}) {
    try {
      parse_ball_overrides({bad}, set());
      ADD_FAILURE() << bad;
    } catch (const std::invalid_argument& e) {
      const std::string what = e.what();
      EXPECT_EQ(what.rfind(std::string("--ball '") + bad + "'", 0), 0u) << what;
      EXPECT_EQ(what.find('\n'), std::string::npos);
    }
  }
  EXPECT_THROW(parse_ball_overrides({"north:grey=1,2,30", "north:grey=5,6,30"}, set()), std::invalid_argument);
}

}  // namespace
}  // namespace rsibr
