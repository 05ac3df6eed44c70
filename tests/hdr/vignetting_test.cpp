// Vignetting (hdr/vignetting.h): estimated from chessboard images rendered through capture/'s lens
// with a known fall-off (the boards lit evenly or with a gradient across each), exposed by the
// sensor model (shot and read noise, 16-bit linear codes), against the truth; and divided out.
#include "hdr/vignetting.h"

#include "capture/camera_response.h"
#include "capture/chessboard.h"
#include "capture/sensor_noise.h"

#include <gtest/gtest.h>

#include <cmath>

namespace rsibr {
namespace {

const LensModel kLens = LensModel::pinhole(450, 480, 360);

// The boards' codes through `truth` (and a light gradient of `gradient` per half board width).
std::vector<VignettingBoard> boards(const Vignetting& truth, int count, double gradient, std::uint64_t seed) {
  const RayTable rays(kLens);
  SynthChessboards spec;
  spec.count = count;
  spec.corners = 10;
  spec.spacing_m = 0.03;
  const SensorNoise noise{0.7 * 30000 / 0.9, 30000, 4};
  const CameraResponse linear("linear");
  std::vector<VignettingBoard> out;
  for (int i = 0; i < count; ++i) {
    const ChessboardShot shot = render_chessboard(kLens, rays, spec, i, seed, 1);
    cv::Mat lit(shot.reflectance.size(), CV_32FC3);
    const Vec2 c = shot.corners[shot.corners.size() / 2];
    for (int y = 0; y < lit.rows; ++y)
      for (int x = 0; x < lit.cols; ++x) {
        const double light = 1 + gradient * (x - c.x()) / 120;
        const float v = float(shot.reflectance.at<float>(y, x) * truth.at(x, y) * light);
        lit.at<cv::Vec3f>(y, x) = cv::Vec3f(v, v, v);
      }
    const cv::Mat codes = expose_bracket(lit, 1.0, noise, linear, 65535, seed, 0xB0000 + std::uint64_t(i));
    cv::Mat c16;
    codes.convertTo(c16, CV_16UC3);
    out.push_back({"board" + std::to_string(i), c16, shot.corners, 10});
  }
  return out;
}

Vignetting truth_model(double k1, double k2, double k3) {
  Vignetting v = Vignetting::none(480, 360, Vec2(239.5, 179.5));
  v.k = {k1, k2, k3};
  return v;
}

TEST(Vignetting, ALensFallOffIsRecoveredToAPercentWhereTheBoardsReachAndATwelfthOfAStopAtTheCorner) {
  for (const auto& k : {std::array<double, 3>{-0.3, 0, 0}, std::array<double, 3>{-0.45, -0.15, 0.05}}) {
    const Vignetting truth = truth_model(k[0], k[1], k[2]);
    const VignettingEstimate e =
        estimate_vignetting(boards(truth, 8, 0, 3), ResponseCurve::identity(65535), truth.centre, 480, 360);
    ASSERT_GT(e.degree, 0) << e.note;
    EXPECT_EQ(e.boards, 8);
    EXPECT_GT(e.squares, 200);
    // Where the squares reach, the model is the truth to 1%; at the corner, extrapolated from
    // squares that reach r ~ 0.6, to 0.08 stops (measured 0.003 and 0.052).
    for (double r : {0.2, 0.4, 0.6, e.max_r}) {
      const double x = truth.centre.x() + r * truth.r_corner;
      EXPECT_NEAR(e.model.at(x, truth.centre.y()) / truth.at(x, truth.centre.y()), 1.0, 0.01) << "r " << r;
    }
    EXPECT_NEAR(e.model.corner_stops(), truth.corner_stops(), 0.08);
    EXPECT_LT(e.rms, 0.01);
  }
}

// Boards lit unevenly (20% across each, as by a window) do not bias it: a linear gradient is not
// vignetting.
TEST(Vignetting, UnevenlyLitBoardsDoNotBiasTheEstimate) {
  const Vignetting truth = truth_model(-0.3, 0, 0);
  const VignettingEstimate e =
      estimate_vignetting(boards(truth, 8, 0.1, 5), ResponseCurve::identity(65535), truth.centre, 480, 360);
  ASSERT_GT(e.degree, 0);
  for (double r : {0.2, 0.4, e.max_r}) {
    const double x = truth.centre.x() + r * truth.r_corner;
    EXPECT_NEAR(e.model.at(x, truth.centre.y()) / truth.at(x, truth.centre.y()), 1.0, 0.015) << "r " << r;
  }
  EXPECT_NEAR(e.model.corner_stops(), truth.corner_stops(), 0.08);  // measured 0.067 (extrapolated)
}

TEST(Vignetting, AFlatLensGivesNoneWithinAHundredthOfAStop) {
  const Vignetting truth = truth_model(0, 0, 0);
  const VignettingEstimate e =
      estimate_vignetting(boards(truth, 6, 0, 7), ResponseCurve::identity(65535), truth.centre, 480, 360);
  ASSERT_GT(e.degree, 0);
  EXPECT_LT(std::abs(e.model.corner_stops()), 0.01 + 2 * e.corner_sigma_stops);
  EXPECT_LT(std::abs(e.model.corner_stops()), 0.03);
}

TEST(Vignetting, FewerThanThreeBoardsGiveNoEstimateAndSaySo) {
  const Vignetting truth = truth_model(-0.3, 0, 0);
  const VignettingEstimate e =
      estimate_vignetting(boards(truth, 2, 0, 3), ResponseCurve::identity(65535), truth.centre, 480, 360);
  EXPECT_EQ(e.degree, 0);
  EXPECT_TRUE(e.model.is_identity());
  EXPECT_NE(e.note.find("need at least 3"), std::string::npos);
}

// Dividing the model out of an image it darkened gives the flat image back; the variance by v^2.
TEST(Vignetting, DividingItOutRestoresTheFlatImage) {
  const Vignetting v = truth_model(-0.45, -0.15, 0.05);
  MergedImage m;
  m.radiance = cv::Mat(360, 480, CV_32FC3);
  m.variance = cv::Mat(360, 480, CV_32FC3);
  for (int y = 0; y < 360; ++y)
    for (int x = 0; x < 480; ++x) {
      const float a = float(v.at(x, y));
      m.radiance.at<cv::Vec3f>(y, x) = cv::Vec3f(2 * a, a, 0.5f * a);
      m.variance.at<cv::Vec3f>(y, x) = cv::Vec3f(a * a, a * a, a * a);
    }
  divide_vignetting(m, v);
  cv::Mat flat(360, 480, CV_32FC3, cv::Scalar(2, 1, 0.5));
  EXPECT_LT(cv::norm(m.radiance, flat, cv::NORM_INF), 1e-5);
  EXPECT_LT(cv::norm(m.variance, cv::Mat(360, 480, CV_32FC3, cv::Scalar::all(1)), cv::NORM_INF), 1e-5);
  EXPECT_GT(v.corner_stops(), 0.8);
}

TEST(Vignetting, TheJsonRoundTripsAndABadModelIsRefused) {
  const Vignetting v = truth_model(-0.2, 0.01, -0.02);
  const Vignetting back = vignetting_from_json(vignetting_json(v), "v.json");
  EXPECT_EQ(back.k, v.k);
  EXPECT_EQ(back.centre, v.centre);
  EXPECT_EQ(back.r_corner, v.r_corner);
  nlohmann::json bad = vignetting_json(v);
  bad["k"] = {-1.5, 0, 0};  // negative at the corner
  EXPECT_THROW(vignetting_from_json(bad, "v.json"), std::invalid_argument);
  bad["k"] = {0, 0};
  EXPECT_THROW(vignetting_from_json(bad, "v.json"), std::invalid_argument);
}

}  // namespace
}  // namespace rsibr
