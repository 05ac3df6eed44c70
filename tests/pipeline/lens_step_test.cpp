// The lens step (pipeline/lens_step.h) on the cases that need no ball: a measured lens passes
// through byte for byte in its intrinsics, a metadata lens with nothing to refine it keeps its
// focal length and says why, and a lens with no focal length at all is an error naming --lens.
#include "pipeline/lens_step.h"

#include "core/test_data.h"

#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

namespace rsibr {
namespace {

LensStep step_with(const testing::TempDir& dir, const std::string& source, double sigma) {
  const LensModel lens("LENSMODEL_OPENCV4", {410, 412, 159.5, 119.5, -0.1, 0.02, 0, 0}, 320, 240);
  lens.write(dir.path() / "camera.cameramodel");
  LensStep s;
  s.calibrated = dir.path() / "camera.cameramodel";
  s.source = source;
  s.prior_sigma_relative = sigma;
  s.out = dir.path() / "lens.cameramodel";
  return s;
}

TEST(LensStep, AMeasuredLensPassesThroughUnchanged) {
  testing::TempDir dir;
  const LensStep s = step_with(dir, "chessboards", 0);
  const nlohmann::json j = run_lens_step(s);
  EXPECT_FALSE(j["refined"].get<bool>());
  EXPECT_NE(j["why"].get<std::string>().find("measured"), std::string::npos) << j.dump();
  EXPECT_EQ(LensModel::read(s.out).intrinsics(), LensModel::read(s.calibrated).intrinsics());
  EXPECT_EQ(LensModel::read(s.out).name(), "LENSMODEL_OPENCV4");
}

TEST(LensStep, AMetadataLensWithNoBallOutlineKeepsItsFocalLengthAndSaysWhy) {
  testing::TempDir dir;
  const LensStep s = step_with(dir, "exif", 0.036);
  const nlohmann::json j = run_lens_step(s);
  EXPECT_FALSE(j["refined"].get<bool>());
  EXPECT_NE(j["why"].get<std::string>().find("no ball outline"), std::string::npos) << j.dump();
  EXPECT_DOUBLE_EQ(j["prior_sigma_px"].get<double>(), 0.036 * 410);
  EXPECT_EQ(LensModel::read(s.out).intrinsics(), LensModel::read(s.calibrated).intrinsics());
  LensStep off = step_with(dir, "lensfun", 0.03);
  off.refine = false;
  EXPECT_NE(run_lens_step(off)["why"].get<std::string>().find("--no-self-calibration"), std::string::npos);
}

TEST(LensStep, NoFocalLengthAndNoOutlineIsAnErrorNamingTheWayOut) {
  testing::TempDir dir;
  LensStep s = step_with(dir, "outlines", 0);
  for (bool refine : {true, false}) {
    s.refine = refine;
    try {
      run_lens_step(s);
      ADD_FAILURE() << "no error";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("--lens FILE"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("no focal length"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace rsibr
