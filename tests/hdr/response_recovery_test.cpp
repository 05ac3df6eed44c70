// Response recovery: the curve comes back within a stated tolerance, identically on every run, and
// held-out error picks the simplest model the data supports.
#include "hdr/bracket_synth.h"
#include "hdr/nnls.h"
#include "hdr/response_recovery.h"

#include "core/test_data.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

namespace rsibr {
namespace {

using testing::BracketCamera;

// Seven brackets two stops apart (the usual bracketing), or in irregular steps.
BracketSet synth_set(const BracketCamera& cam, unsigned seed, bool irregular = false) {
  const cv::Mat L = testing::ramp_scene(96, 192, -3.5, 1.0);
  const auto e =
      irregular ? std::vector<double>{1.0 / 64, 3.0 / 64, 10.0 / 64, 40.0 / 64, 110.0 / 64, 500.0 / 64, 1600.0 / 64}
                : testing::exposure_series(1.0 / 64, 4.0, 7);
  return make_brackets(testing::synthesize(L, e, cam, seed), e);
}

BracketCamera eight_bit(std::function<double(int, double)> response) {
  BracketCamera cam;
  cam.max_code = 255;
  cam.response = std::move(response);
  return cam;
}

// Truth: X(z) = u^-1(z / max), by bisection on the monotone response.
double true_inverse(const BracketCamera& cam, int c, double z) {
  double lo = 0, hi = 1;
  for (int i = 0; i < 60; ++i) {
    const double mid = 0.5 * (lo + hi);
    (cam.response(c, mid) * cam.max_code < z ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

// Worst relative error of X(z)/X(128) over codes 16..242 (the curve is known up to scale; codes
// below 16 sit in the read noise of this camera and carry little weight in any merge).
double worst_curve_error(const ResponseCurve& curve, const BracketCamera& cam) {
  double worst = 0;
  for (int c = 0; c < 3; ++c) {
    const double s_rec = curve.linear(c, 128), s_true = true_inverse(cam, c, 128);
    for (int z = 16; z <= 242; ++z) {
      const double rec = curve.linear(c, z) / s_rec, tru = true_inverse(cam, c, z) / s_true;
      worst = std::max(worst, std::abs(rec / tru - 1));
    }
  }
  return worst;
}

TEST(ResponseRecovery, DebevecRecoversAnSCurveWithinThreePercent) {
  const BracketCamera cam = eight_bit(testing::s_curve);
  RecoveryOptions o;
  o.model = "debevec";
  const ResponseRecovery r = recover_response(synth_set(cam, 1, true), o);
  EXPECT_EQ(r.curve.model, "debevec");
  EXPECT_NO_THROW(r.curve.validate());
  EXPECT_LT(worst_curve_error(r.curve, cam), 0.03);
}

TEST(ResponseRecovery, DebevecWithConstantRatioBracketsIsWithinEightPercent) {
  // Two-stop steps leave the log-periodic ambiguity (response_recovery.h); smoothness bounds it.
  const BracketCamera cam = eight_bit(testing::s_curve);
  RecoveryOptions o;
  o.model = "debevec";
  EXPECT_LT(worst_curve_error(recover_response(synth_set(cam, 1), o).curve, cam), 0.08);
}

TEST(ResponseRecovery, RobertsonRecoversAnSCurveWithinTenPercent) {
  const BracketCamera cam = eight_bit(testing::s_curve);
  RecoveryOptions o;
  o.model = "robertson";
  const ResponseRecovery r = recover_response(synth_set(cam, 2, true), o);
  EXPECT_LT(worst_curve_error(r.curve, cam), 0.10);
}

TEST(ResponseRecovery, PolynomialRecoversAnSCurveWithinThreePercent) {
  const BracketCamera cam = eight_bit(testing::s_curve);
  RecoveryOptions o;
  o.model = "polynomial";
  EXPECT_LT(worst_curve_error(recover_response(synth_set(cam, 3), o).curve, cam), 0.03);
}

TEST(ResponseRecovery, CurveIsIdenticalOnEveryRun) {
  const BracketCamera cam = eight_bit(testing::s_curve);
  const ResponseRecovery a = recover_response(synth_set(cam, 3));
  const ResponseRecovery b = recover_response(synth_set(cam, 3));
  EXPECT_EQ(a.curve.model, b.curve.model);
  for (int c = 0; c < 3; ++c) EXPECT_EQ(a.curve.knots[std::size_t(c)], b.curve.knots[std::size_t(c)]);
  ASSERT_EQ(a.candidates.size(), b.candidates.size());
  for (std::size_t k = 0; k < a.candidates.size(); ++k)
    EXPECT_EQ(a.candidates[k].held_out_error, b.candidates[k].held_out_error);
}

TEST(ResponseRecovery, HeldOutErrorChoosesIdentityForLinearInput) {
  BracketCamera cam;  // 16-bit linear
  const ResponseRecovery r = recover_response(synth_set(cam, 4));
  EXPECT_EQ(r.curve.model, "identity");
}

TEST(ResponseRecovery, HeldOutErrorChoosesGammaForAPowerLaw) {
  const BracketCamera cam = eight_bit([](int c, double X) { return std::pow(X, 1.0 / (2.0 + 0.2 * c)); });
  const ResponseRecovery r = recover_response(synth_set(cam, 5));
  EXPECT_EQ(r.curve.model, "gamma");
  for (int c = 0; c < 3; ++c)
    EXPECT_NEAR(r.curve.parameters["gamma"][std::size_t(c)].get<double>(), 2.0 + 0.2 * c, 0.05);
}

TEST(ResponseRecovery, HeldOutErrorRejectsAPowerLawForAnSCurve) {
  const ResponseRecovery r = recover_response(synth_set(eight_bit(testing::s_curve), 6));
  EXPECT_NE(r.curve.model, "identity");
  EXPECT_NE(r.curve.model, "gamma");
  double gamma_error = 0, chosen = 1e30;
  for (const auto& c : r.candidates) {
    if (c.model == "gamma") gamma_error = c.held_out_error;
    if (c.model == r.curve.model) chosen = std::min(chosen, c.held_out_error);
  }
  EXPECT_GT(gamma_error, 1.5 * chosen);
}

TEST(ResponseRecovery, CurveSurvivesSaveAndLoad) {
  testing::TempDir dir;
  const ResponseRecovery r = recover_response(synth_set(eight_bit(testing::s_curve), 7));
  const auto path = dir.path() / "camera.response.json";
  save_response(path, r.curve, {{"camera", "test"}});
  const ResponseCurve back = load_response(path);
  EXPECT_EQ(back.model, r.curve.model);
  EXPECT_EQ(back.max_code, 255);
  for (int c = 0; c < 3; ++c)
    for (std::size_t k = 0; k < back.knots[std::size_t(c)].size(); ++k)
      EXPECT_DOUBLE_EQ(back.knots[std::size_t(c)][k], r.curve.knots[std::size_t(c)][k]);
}

TEST(ResponseRecovery, MalformedResponseFileIsAnErrorNamingIt) {
  testing::TempDir dir;
  const auto path = dir.path() / "bad.json";
  std::ofstream(path) << R"({"rsibr_response": 1, "model": "x", "max_code": 255, "knots": [[0, 1.5], [0, 1], [0, 1]]})";
  try {
    load_response(path);
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("bad.json"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("top knot"), std::string::npos);
  }
}

TEST(ResponseRecovery, AllBlackOrAllWhiteInputIsAClearError) {
  for (std::uint16_t v : {std::uint16_t(0), std::uint16_t(65535)}) {
    std::vector<cv::Mat> imgs(5, cv::Mat(64, 64, CV_16UC3, cv::Scalar::all(v)));
    const BracketSet b = make_brackets(imgs, testing::exposure_series(0.01, 2, 5));
    EXPECT_THROW(recover_response(b), std::runtime_error);
  }
}

TEST(ResponseRecovery, OneBracketIsAClearError) {
  const BracketSet b = make_brackets({cv::Mat(16, 16, CV_8UC3, cv::Scalar::all(100))}, {0.01});
  EXPECT_THROW(recover_response(b), std::runtime_error);
}

TEST(Nnls, MatchesTheActiveSetSolutionOfASmallProblem) {
  // min |A x - b|^2, x >= 0, with A = I and b = (1, -2, 3): x = (1, 0, 3).
  const Eigen::MatrixXd Q = Eigen::MatrixXd::Identity(3, 3);
  const Eigen::VectorXd p = (Eigen::VectorXd(3) << 1, -2, 3).finished();
  const Eigen::VectorXd x = nnls_gram(Q, p);
  EXPECT_NEAR(x(0), 1, 1e-12);
  EXPECT_EQ(x(1), 0);
  EXPECT_NEAR(x(2), 3, 1e-12);
  // A coupled problem: KKT conditions hold (gradient >= 0 where x = 0, = 0 where x > 0).
  Eigen::MatrixXd A(4, 3);
  A << 1, 2, 0, 0, 1, 1, 1, 0, 1, 2, 1, 1;
  const Eigen::VectorXd b = (Eigen::VectorXd(4) << -1, 2, -3, 1).finished();
  const Eigen::VectorXd y = nnls_gram(A.transpose() * A, A.transpose() * b);
  const Eigen::VectorXd grad = A.transpose() * (A * y - b);
  for (int i = 0; i < 3; ++i) {
    EXPECT_GE(y(i), 0);
    if (y(i) > 0)
      EXPECT_NEAR(grad(i), 0, 1e-9);
    else
      EXPECT_GE(grad(i), -1e-9);
  }
}

}  // namespace
}  // namespace rsibr
