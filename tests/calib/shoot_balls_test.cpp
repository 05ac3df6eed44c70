// The balls of a shoot found once (calib/balls/shoot_balls.h) and kept in DIR/balls.json
// (calib/balls/balls_file.h), on rendered views of a chrome and a grey ball: every listed ball has
// a status, a ball given by hand is taken as given, the file gives back what was found to the bit
// and refuses what is not such a file, and a later step's lens refits the same outline pixels into
// the cone that lens would have located.
#include "calib/balls/balls_file.h"
#include "calib/balls/shoot_balls.h"

#include "calib_cases.h"
#include "core/test_data.h"

#include <gtest/gtest.h>

#include <fstream>
#include <stdexcept>

namespace rsibr {
namespace {

const LensModel& lens() {
  static const LensModel l = LensModel::pinhole(600, 400, 300);
  return l;
}

const std::vector<testing::RenderedView>& views() {
  static const std::vector<testing::RenderedView> v = [] {
    const SynthScene scene = testing::rig_scene(lens(), 1.0, false);
    return std::vector<testing::RenderedView>{testing::render_view(scene, 0, 0.002),
                                              testing::render_view(scene, 1, 0.002)};
  }();
  return v;
}

// The truth's circle of ball b in view v: centre pixel and image radius.
BallGuess truth(std::size_t v, int b) {
  const Vec3 c = testing::ball_centre_cam(views()[v], b);
  return {lens().project(c), 600 * std::tan(std::asin(0.05 / c.norm()))};
}

ShootBallsInput input(const std::vector<ListedBall>& listed) {
  ShootBallsInput in;
  in.views = {"a", "b"};
  in.read_view = [](std::size_t v) { return ViewImage{views()[v].radiance, {}, {}}; };
  in.lens = lens();
  in.listed = listed;
  return in;
}

const std::vector<ListedBall> kRig = {{"chrome", BallKind::chrome, 0.1}, {"grey", BallKind::grey, 0.1}};

TEST(ShootBalls, EveryListedBallHasAStatusAndAGivenBallIsTakenAsGiven) {
  ShootBallsInput in = input(kRig);
  in.views.push_back("blank");  // no ball in it
  in.read_view = [](std::size_t v) {
    return ViewImage{v < 2 ? views()[v].radiance : cv::Mat(300, 400, CV_32FC3, cv::Scalar(0.5, 0.5, 0.5)), {}, {}};
  };
  in.given = {{std::nullopt, truth(0, 1)}, {}, {}};
  int seen = 0;
  in.seen = [&](std::size_t, const cv::Mat& radiance, const ViewCandidates& vc) {
    EXPECT_EQ(radiance.cols, 400);
    EXPECT_EQ(vc.pick.size(), 2u);
    ++seen;
  };
  const ShootBalls found = find_shoot_balls(in);
  EXPECT_EQ(seen, 3);
  ASSERT_EQ(found.views.size(), 3u);
  for (std::size_t v = 0; v < 2; ++v) {
    const FoundView& fv = found.views[v];
    EXPECT_EQ(fv.width, 400);
    EXPECT_EQ(fv.height, 300);
    EXPECT_TRUE(fv.lens == lens());
    ASSERT_EQ(fv.balls.size(), 2u);
    EXPECT_EQ(fv.balls[0].status, "found") << fv.name;
    EXPECT_EQ(fv.balls[1].status, v == 0 ? "given" : "found") << fv.name;
    for (int b = 0; b < 2; ++b) {
      ASSERT_GE(fv.balls[std::size_t(b)].candidate, 0) << fv.name << " ball " << b;
      const BallLocation& loc = fv.candidates.at(std::size_t(fv.balls[std::size_t(b)].candidate)).loc;
      EXPECT_LT((loc.centre_px - truth(v, b).centre_px).norm(), 1.0) << fv.name << " ball " << b;
      EXPECT_NEAR(loc.radius_px, truth(v, b).radius_px, 1.0) << fv.name << " ball " << b;
    }
  }
  for (const FoundBall& b : found.views[2].balls) {
    EXPECT_EQ(b.status, "missing");
    EXPECT_EQ(b.candidate, -1);
  }
  EXPECT_EQ(main_ball(found.views[0], found.listed), found.views[0].balls[0].candidate);  // the chrome ball
  EXPECT_EQ(main_ball(found.views[2], found.listed), -1);
}

// A ball given where the search also finds it is one ball: the given fit takes the found
// candidate's place (a second circle there would be another ball overlapping it, whose disc
// later steps mask).
TEST(ShootBalls, ABallGivenWhereTheSearchFoundItIsOneCandidate) {
  const ShootBalls searched = find_shoot_balls(input(kRig));
  ShootBallsInput in = input(kRig);
  in.given = {{truth(0, 0), std::nullopt}, {}};
  const ShootBalls found = find_shoot_balls(in);
  const FoundView& fv = found.views[0];
  ASSERT_EQ(fv.candidates.size(), searched.views[0].candidates.size());
  EXPECT_EQ(fv.balls[0].status, "given");
  EXPECT_EQ(fv.balls[0].candidate, searched.views[0].balls[0].candidate);
  EXPECT_EQ(fv.balls[1].candidate, searched.views[0].balls[1].candidate);
  for (std::size_t i = 0; i < fv.candidates.size(); ++i)
    for (std::size_t j = 0; j < i; ++j)
      EXPECT_FALSE(same_circle(fv.candidates[i].loc, fv.candidates[j].loc)) << i << " and " << j;
}

TEST(ShootBalls, NoBallListedMeansOneChromeBall) {
  const ShootBalls found = find_shoot_balls(input({}));
  ASSERT_EQ(found.listed.size(), 1u);
  EXPECT_EQ(found.listed[0].kind, BallKind::chrome);
  EXPECT_EQ(found.views[0].balls.at(0).status, "found");
}

TEST(BallsFile, WritingAndReadingGivesBackTheSameBallsToTheBit) {
  testing::TempDir dir;
  ShootBallsInput in = input(kRig);
  in.given = {{}, {truth(1, 0), std::nullopt}};
  const ShootBalls found = find_shoot_balls(in);
  write_balls_file(dir.path() / "balls.json", found);
  const ShootBalls back = read_balls_file(dir.path() / "balls.json");
  ASSERT_EQ(back.listed.size(), 2u);
  EXPECT_EQ(back.listed[1].name, "grey");
  EXPECT_EQ(back.listed[1].diameter_m, 0.1);
  ASSERT_EQ(back.views.size(), found.views.size());
  for (std::size_t v = 0; v < found.views.size(); ++v) {
    const FoundView &a = found.views[v], &b = back.views[v];
    EXPECT_EQ(a.name, b.name);
    EXPECT_TRUE(a.lens == b.lens);
    ASSERT_EQ(a.candidates.size(), b.candidates.size());
    for (std::size_t k = 0; k < a.candidates.size(); ++k) {
      const BallCandidate &x = a.candidates[k], &y = b.candidates[k];
      EXPECT_EQ(x.loc.outline_px, y.loc.outline_px);
      EXPECT_EQ(x.loc.fit.residual_px, y.loc.fit.residual_px);
      EXPECT_EQ(x.loc.fit.cone.axis, y.loc.fit.cone.axis);
      EXPECT_EQ(x.loc.fit.cone.half_angle, y.loc.fit.cone.half_angle);
      EXPECT_EQ(x.loc.centre_px, y.loc.centre_px);
      EXPECT_EQ(x.loc.radius_px, y.loc.radius_px);
      EXPECT_EQ(x.mirror_score, y.mirror_score);
      EXPECT_EQ(x.diffuse_residual, y.diffuse_residual);
      EXPECT_EQ(x.cut, y.cut);
    }
    for (std::size_t i = 0; i < a.balls.size(); ++i) {
      EXPECT_EQ(a.balls[i].status, b.balls[i].status);
      EXPECT_EQ(a.balls[i].candidate, b.balls[i].candidate);
    }
  }
  EXPECT_EQ(back.views[1].balls[0].status, "given");
  // The summary's rig offset: the grey ball's centre from the chrome ball's, 0.14 m = 2.8 chrome radii.
  const nlohmann::json j = balls_summary_json(back);
  const auto& o = j["views"][0]["balls"][1]["offset_from_chrome"];
  ASSERT_TRUE(o.is_array()) << j.dump();
  EXPECT_NEAR(std::hypot(o[0].get<double>(), o[1].get<double>(), o[2].get<double>()), 2.8, 0.1) << o.dump();
  EXPECT_TRUE(j["views"][0]["balls"][0]["offset_from_chrome"].is_null());
  EXPECT_GT(j["views"][0]["balls"][0]["confidence"].get<double>(), 0.5);
}

TEST(BallsFile, AFileThatIsNotABallsFileIsAnErrorNamingIt) {
  testing::TempDir dir;
  const std::filesystem::path good = dir.path() / "balls.json";
  write_balls_file(good, find_shoot_balls(input(kRig)));
  std::ifstream in(good);
  nlohmann::json j = nlohmann::json::parse(in);
  auto refused = [&](nlohmann::json bad, const std::string& why) {
    const std::filesystem::path f = dir.path() / "bad.json";
    std::ofstream(f) << bad.dump();
    try {
      read_balls_file(f);
      ADD_FAILURE() << "accepted: " << why;
    } catch (const std::invalid_argument& e) {
      EXPECT_EQ(std::string(e.what()).rfind(f.string() + ": ", 0), 0u) << e.what();
      EXPECT_NE(std::string(e.what()).find(why), std::string::npos) << e.what();
    }
  };
  nlohmann::json bad = j;
  bad["views"][0]["balls"][0]["candidate"] = 99;
  refused(bad, "candidate 99");
  bad = j;
  bad["views"][0]["balls"][1]["status"] = "maybe";
  refused(bad, "status 'maybe'");
  bad = j;
  bad["version"] = 7;
  refused(bad, "version 7");
  bad = j;
  bad["views"][0].erase("candidates");
  refused(bad, "candidates");
  bad = j;
  bad["views"][0]["candidates"][0]["outline_px"].push_back(1.0);
  refused(bad, "x, y pairs");
  const std::filesystem::path cut = dir.path() / "cut.json";
  std::ofstream(cut) << j.dump().substr(0, 100);
  EXPECT_THROW(read_balls_file(cut), std::invalid_argument);
  EXPECT_THROW(read_balls_file(dir.path() / "none.json"), std::invalid_argument);
}

TEST(BallsFile, BallsOfAnotherPhotoSetAreRefused) {
  const ShootBalls found = find_shoot_balls(input(kRig));
  EXPECT_NO_THROW(check_listed_balls(found, kRig, "balls.json"));
  try {
    check_listed_balls(found, {kRig[0], {"grey", BallKind::grey, 0.2}}, "balls.json");
    FAIL() << "another diameter was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("are not the photo set's"), std::string::npos) << e.what();
  }
  EXPECT_THROW(check_listed_balls(found, {kRig[0]}, "balls.json"), std::invalid_argument);
}

TEST(ShootBalls, ThroughTheSameLensCandidatesAreUnchangedThroughAnotherTheyAreRefitted) {
  const ShootBalls found = find_shoot_balls(input(kRig));
  const FoundView& v = found.views[0];
  const ViewCandidates same = candidates_for_lens(v, lens());
  ASSERT_EQ(same.cands.size(), v.candidates.size());
  for (std::size_t k = 0; k < same.cands.size(); ++k)
    EXPECT_EQ(same.cands[k].loc.fit.cone.axis, v.candidates[k].loc.fit.cone.axis);
  EXPECT_EQ(same.pick, (std::vector<int>{v.balls[0].candidate, v.balls[1].candidate}));
  // A focal length 4% longer (the lens step's refinement can move it so far): the outline is the
  // same pixels, the cone narrower. The refit agrees with the cone located through that lens.
  const LensModel longer = LensModel::pinhole(624, 400, 300);
  const ViewCandidates refit = candidates_for_lens(v, longer);
  for (int b = 0; b < 2; ++b) {
    const BallCandidate& r = refit.cands[std::size_t(refit.pick[std::size_t(b)])];
    const BallCandidate& o = v.candidates[std::size_t(v.balls[std::size_t(b)].candidate)];
    const BallLocation located = locate_ball(views()[0].radiance, longer, {o.loc.centre_px, o.loc.radius_px});
    EXPECT_LT(std::acos(std::min(1.0, r.loc.fit.cone.axis.dot(located.fit.cone.axis))), 2e-4) << "ball " << b;
    EXPECT_NEAR(r.loc.fit.cone.half_angle, located.fit.cone.half_angle, 2e-3 * located.fit.cone.half_angle);
    EXPECT_NEAR(r.loc.fit.cone.half_angle / o.loc.fit.cone.half_angle, 600.0 / 624.0, 0.01) << "ball " << b;
    EXPECT_LT((r.loc.centre_px - o.loc.centre_px).norm(), 0.05) << "ball " << b;
    EXPECT_NEAR(r.inlier_fraction, o.inlier_fraction, 0.05);
    EXPECT_EQ(r.mirror_score, o.mirror_score);  // appearance is the image's, not the lens's
  }
}

}  // namespace
}  // namespace rsibr
