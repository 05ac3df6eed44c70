// capture/chessboard.h: boards rendered through the lens are found by mrgingham, every corner
// where the truth says it is.
#include "capture/chessboard.h"

#include "capture/sensor_noise.h"
#include "core/test_data.h"
#include "formats/image_codecs.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <sstream>

namespace rsibr {
namespace {

bool have_mrgingham() { return std::system("command -v mrgingham >/dev/null 2>&1") == 0; }

std::vector<Vec2> run_mrgingham(const std::string& image, int gridn) {
  const std::string cmd = "mrgingham --jobs 1 --gridn " + std::to_string(gridn) + " '" + image + "' 2>/dev/null";
  FILE* p = popen(cmd.c_str(), "r");
  std::vector<Vec2> out;
  if (!p) return out;
  char line[512];
  while (std::fgets(line, sizeof line, p)) {
    if (line[0] == '#') continue;
    std::istringstream s(line);
    std::string file, xs, ys;
    s >> file >> xs >> ys;
    if (xs == "-") continue;
    out.emplace_back(std::stod(xs), std::stod(ys));
  }
  pclose(p);
  return out;
}

TEST(Chessboard, MrginghamFindsEveryCornerWhereTheTruthPutsIt) {
  if (!have_mrgingham()) GTEST_SKIP() << "mrgingham not installed (scripts/install-deps.sh installs it)";
  testing::TempDir dir;
  const LensModel lens("LENSMODEL_OPENCV8", {520, 520, 319.5, 239.5, -0.12, 0.03, 0.0005, -0.0003, 0, 0.01, 0, 0.005},
                       640, 480);
  const RayTable rays(lens);
  SynthChessboards boards;
  boards.count = 3;
  boards.corners = 10;
  boards.spacing_m = 0.03;
  const SensorNoise noise{0.7 * 2e4 / 0.9, 2e4, 3};
  double worst = 0;
  Vec2 bias(0, 0);
  for (int i = 0; i < boards.count; ++i) {
    const ChessboardShot shot = render_chessboard(lens, rays, boards, i, 42, 3);
    ASSERT_EQ(shot.corners.size(), 100u);
    const cv::Mat codes =
        expose_bracket(shot.reflectance, 1.0, noise, CameraResponse("srgb"), 255, 42, std::uint64_t(i));
    cv::Mat png;
    codes.convertTo(png, CV_8U);
    const std::string file = dir.file("board" + std::to_string(i) + ".png");
    ASSERT_TRUE(rsibr::write_image(file, png));
    const std::vector<Vec2> found = run_mrgingham(file, 10);
    ASSERT_EQ(found.size(), 100u) << "board " << i;
    for (const Vec2& t : shot.corners) {
      double best = 1e9;
      Vec2 offset(0, 0);
      for (const Vec2& f : found)
        if ((f - t).norm() < best) best = (f - t).norm(), offset = f - t;
      worst = std::max(worst, best);
      bias += offset / 300.0;
    }
  }
  // mrgingham's accuracy on noisy, tilted 8-bit boards (measured 0.48 px worst); no systematic
  // offset, so both use the same pixel convention (mrcal's: (0,0) is the top-left pixel's centre).
  EXPECT_LT(worst, 0.75) << "worst corner distance " << worst << " px";
  EXPECT_LT(bias.norm(), 0.05) << "mean offset " << bias.transpose();
  std::cout << "mrgingham: worst distance to the true corner " << worst << " px, mean offset " << bias.transpose()
            << " px\n";
}

TEST(Chessboard, PosesAreSeededAndKeepEveryCornerInside) {
  const LensModel lens = LensModel::pinhole(400, 320, 240);
  const RayTable rays(lens);
  SynthChessboards boards;
  boards.corners = 6;
  boards.spacing_m = 0.02;
  const ChessboardShot a = render_chessboard(lens, rays, boards, 0, 1, 1),
                       b = render_chessboard(lens, rays, boards, 0, 1, 1);
  const ChessboardShot c = render_chessboard(lens, rays, boards, 1, 1, 1);
  EXPECT_EQ(cv::norm(a.reflectance, b.reflectance, cv::NORM_INF), 0);
  EXPECT_NE(a.corners[0], c.corners[0]);
  for (const Vec2& p : c.corners) EXPECT_TRUE(lens.in_image(p));
  // A corner is where four squares meet: the reflectance around it alternates.
  const Vec2 p = a.corners[14];
  const int x = int(std::lround(p.x())), y = int(std::lround(p.y()));
  const float tl = a.reflectance.at<float>(y - 3, x - 3), tr = a.reflectance.at<float>(y - 3, x + 3);
  const float bl = a.reflectance.at<float>(y + 3, x - 3), br = a.reflectance.at<float>(y + 3, x + 3);
  EXPECT_GT(std::abs(tl - tr), 0.5f);
  EXPECT_GT(std::abs(tl - bl), 0.5f);
  EXPECT_LT(std::abs(tl - br), 0.2f);
}

}  // namespace
}  // namespace rsibr
