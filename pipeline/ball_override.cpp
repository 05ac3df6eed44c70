#include "pipeline/ball_override.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace rsibr {

std::vector<BallOverride> parse_ball_overrides(const std::vector<std::string>& texts, const PhotoSet& set) {
  std::vector<BallOverride> out;
  for (const std::string& t : texts) {
    auto fail = [&](const std::string& why) { throw std::invalid_argument("--ball '" + t + "': " + why); };
    const auto colon = t.find(':'), eq = t.find('=');
    if (colon == std::string::npos || eq == std::string::npos || eq < colon) fail("expected VIEW:BALL=X,Y,R (pixels)");
    BallOverride o;
    o.view = t.substr(0, colon);
    o.ball = t.substr(colon + 1, eq - colon - 1);
    std::istringstream in(t.substr(eq + 1));
    double x = 0, y = 0, r = 0;
    char c1 = 0, c2 = 0;
    if (!(in >> x >> c1 >> y >> c2 >> r) || c1 != ',' || c2 != ',' || !(in >> std::ws).eof())
      fail("expected VIEW:BALL=X,Y,R (pixels)");
    if (!std::isfinite(x) || !std::isfinite(y) || !(r > 1) || !std::isfinite(r))
      fail("the radius must be > 1 px and every value finite");
    bool view_known = false, ball_known = false;
    for (const PhotoView& v : set.views) view_known |= v.name == o.view;
    for (const BallSpec& b : set.balls) ball_known |= b.name == o.ball;
    if (!view_known) fail("the photo set has no view '" + o.view + "'");
    if (!ball_known) fail("the photo set lists no ball '" + o.ball + "'");
    for (const BallOverride& p : out)
      if (p.view == o.view && p.ball == o.ball) fail("given twice");
    o.guess = {Vec2(x, y), r};
    out.push_back(o);
  }
  return out;
}

std::optional<BallGuess> find_override(const std::vector<BallOverride>& overrides, const std::string& view,
                                       const std::string& ball) {
  for (const BallOverride& o : overrides)
    if (o.view == view && o.ball == ball) return o.guess;
  return std::nullopt;
}

}  // namespace rsibr
