// Registration of brackets (hdr/alignment.h: shifts, hand-cropped sizes) and the merged EXR file.
#include "hdr/alignment.h"
#include "hdr/bracket_synth.h"
#include "hdr/merge.h"
#include "hdr/merged_exr.h"
#include "hdr/response_curve.h"

#include "core/test_data.h"
#include "formats/image_codecs.h"

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

namespace rsibr {
namespace {

TEST(Alignment, MedianThresholdBitmapUndoesASmallShift) {
  // A textured scene (blobs of different radiance), three brackets, the last one shifted.
  cv::Mat L(128, 160, CV_64FC3);
  for (int r = 0; r < L.rows; ++r)
    for (int x = 0; x < L.cols; ++x) {
      const double v = 1.0 + 0.8 * std::sin(x * 0.21) * std::cos(r * 0.17) + 0.5 * ((x / 16 + r / 16) % 2);
      L.at<cv::Vec3d>(r, x) = cv::Vec3d::all(v);
    }
  testing::BracketCamera cam;
  cam.max_code = 255;
  cam.response = [](int, double X) { return std::pow(X, 1 / 2.2); };
  const std::vector<double> e = {0.1, 0.25, 0.6};
  auto imgs = testing::synthesize(L, e, cam, 30);
  const cv::Mat M = (cv::Mat_<double>(2, 3) << 1, 0, 3, 0, 1, -2);  // moves content by (+3, -2)
  cv::warpAffine(imgs[2], imgs[2], M, imgs[2].size(), cv::INTER_NEAREST, cv::BORDER_REPLICATE);
  BracketSet b = make_brackets(imgs, e);
  const auto shifts = align_brackets(b).shifts;
  EXPECT_EQ(shifts[1], cv::Point(0, 0));
  EXPECT_EQ(shifts[0], cv::Point(0, 0));
  EXPECT_EQ(shifts[2], cv::Point(-3, 2));
}

// The textured scene of the tests above and three brackets through a gamma camera with noise.
struct TexturedShoot {
  cv::Mat L;
  std::vector<double> e = {0.1, 0.25, 0.6};
  std::vector<cv::Mat> images;
};

// A scene of level v (CV_64FC1), tinted (v, 0.9 v, 0.8 v), through a gamma camera with noise.
TexturedShoot shoot_of(const cv::Mat& level, unsigned seed) {
  TexturedShoot s;
  s.L.create(level.rows, level.cols, CV_64FC3);
  for (int r = 0; r < level.rows; ++r)
    for (int x = 0; x < level.cols; ++x) {
      const double v = level.at<double>(r, x);
      s.L.at<cv::Vec3d>(r, x) = cv::Vec3d(v, 0.9 * v, 0.8 * v);
    }
  testing::BracketCamera cam;
  cam.max_code = 255;
  cam.response = [](int, double X) { return std::pow(X, 1 / 2.2); };
  s.images = testing::synthesize(s.L, s.e, cam, seed);
  return s;
}

TexturedShoot textured_shoot(unsigned seed = 30) {
  cv::Mat level(128, 160, CV_64FC1);
  for (int r = 0; r < level.rows; ++r)
    for (int x = 0; x < level.cols; ++x)
      level.at<double>(r, x) = 1.0 + 0.8 * std::sin(x * 0.21) * std::cos(r * 0.17) + 0.5 * ((x / 16 + r / 16) % 2);
  return shoot_of(level, seed);
}

ResponseCurve gamma_curve() {
  return ResponseCurve::sampled("gamma", 255, 256, [](int, double u) { return std::pow(u, 2.2); });
}

cv::Mat moved(const cv::Mat& img, int dx, int dy) {
  const cv::Mat M = (cv::Mat_<double>(2, 3) << 1, 0, dx, 0, 1, dy);
  cv::Mat out;
  cv::warpAffine(img, out, M, img.size(), cv::INTER_NEAREST, cv::BORDER_REPLICATE);
  return out;
}

long ghosts(const BracketSet& b) { return merge_brackets(b, gamma_curve(), NoiseModel{}).ghost; }

// Tripod brackets (the same framing, independent noise): the automatic mode moves nothing.
TEST(Alignment, AutomaticAlignmentLeavesTripodBracketsAlone) {
  for (unsigned seed : {1u, 2u, 3u}) {
    BracketSet b = make_brackets(textured_shoot(seed).images, {0.1, 0.25, 0.6});
    const AlignmentResult r = align_brackets(b, Alignment::automatic);
    for (const cv::Point& p : r.shifts) EXPECT_EQ(p, cv::Point(0, 0)) << seed;
    EXPECT_TRUE(b.covered.empty());
  }
}

// A handheld bracket moved by (+3, -2): the automatic mode undoes it (the bitmaps then agree far
// better), marks the edge it uncovered, and the merge then flags no ghosts where the unaligned
// merge flags the scene's every edge.
TEST(Alignment, AHandheldShiftIsUndoneAutomaticallyAndItsUncoveredEdgeLeftOut) {
  TexturedShoot s = textured_shoot();
  s.images[2] = moved(s.images[2], 3, -2);
  const BracketSet unaligned = make_brackets(s.images, s.e);
  BracketSet b = make_brackets(s.images, s.e);
  const AlignmentResult r = align_brackets(b, Alignment::automatic);
  EXPECT_EQ(r.shifts[2], cv::Point(-3, 2));
  EXPECT_LT(r.mismatch_after[2], 0.5 * r.mismatch_before[2]);
  ASSERT_EQ(b.covered.size(), 3u);
  ASSERT_FALSE(b.covered[2].empty());
  EXPECT_EQ(b.covered[2].at<unsigned char>(60, 159), 0);  // the right 3 columns
  EXPECT_EQ(b.covered[2].at<unsigned char>(1, 60), 0);    // the top 2 rows
  EXPECT_NE(b.covered[2].at<unsigned char>(60, 156), 0);
  EXPECT_EQ(cv::countNonZero(b.covered[2] == 0), 128 * 3 + 2 * 157);
  const double px = 128.0 * 160;
  EXPECT_GT(ghosts(unaligned) / px, 0.05);
  EXPECT_LT(ghosts(b) / px, 0.005);
  // On the uncovered edge the other two brackets alone give the radiance, within their noise.
  const MergedImage m = merge_brackets(b, gamma_curve(), NoiseModel{});
  for (int y = 10; y < 120; y += 10) {
    const cv::Vec3f v = m.radiance.at<cv::Vec3f>(y, 158);
    const cv::Vec3d t = s.L.at<cv::Vec3d>(y, 158);
    EXPECT_NEAR(v[1] / t[1], 1.0, 0.1) << y;
    EXPECT_EQ(m.flags.at<unsigned char>(y, 158) & kClipped, 0);
  }
}

// A larger scene without repeats (smoothed random blobs), three brackets through a gamma camera.
TexturedShoot blob_shoot(int rows, int cols, unsigned seed = 7) {
  cv::Mat noise(rows, cols, CV_64FC1);
  cv::RNG rng(seed);
  rng.fill(noise, cv::RNG::UNIFORM, 0.0, 1.0);
  cv::GaussianBlur(noise, noise, cv::Size(0, 0), 2.5);
  cv::normalize(noise, noise, 0.2, 2.0, cv::NORM_MINMAX);
  return shoot_of(noise, seed);
}

// A handheld bracket moved by a sixth of the frame, beyond what six levels of MTB reach (63 px):
// the coarse search finds it and the merge has no ghost left but at the uncovered edge.
TEST(Alignment, AShiftOfASixthOfTheFrameIsUndone) {
  TexturedShoot s = blob_shoot(480, 640);
  s.images[0] = moved(s.images[0], 110, -80);
  const BracketSet unaligned = make_brackets(s.images, s.e);
  BracketSet b = make_brackets(s.images, s.e);
  const AlignmentResult r = align_brackets(b, Alignment::automatic);
  EXPECT_EQ(r.shifts[0], cv::Point(-110, 80));
  EXPECT_EQ(r.rotation_deg[0], 0.0);
  EXPECT_FALSE(r.beyond_search[0]);
  const double px = 480.0 * 640;
  EXPECT_GT(ghosts(unaligned) / px, 0.05);
  EXPECT_LT(ghosts(b) / px, 0.005);
}

// A handheld camera rolls too: a bracket turned by 1.5 degrees and moved is registered with the
// rotation, and its ghosts go with it.
TEST(Alignment, ASmallRollIsUndone) {
  TexturedShoot s = blob_shoot(480, 640, 9);
  cv::Mat M = cv::getRotationMatrix2D(cv::Point2f(319.5f, 239.5f), 1.5, 1.0);
  M.at<double>(0, 2) += 12, M.at<double>(1, 2) -= 7;
  cv::warpAffine(s.images[2], s.images[2], M, s.images[2].size(), cv::INTER_LINEAR, cv::BORDER_REPLICATE);
  const BracketSet unaligned = make_brackets(s.images, s.e);
  BracketSet b = make_brackets(s.images, s.e);
  const AlignmentResult r = align_brackets(b, Alignment::automatic);
  EXPECT_NEAR(r.rotation_deg[2], -1.5, 0.3);  // two angle steps of the finest level (a pixel at the corners each)
  EXPECT_LT(r.mismatch_after[2], 0.3 * r.mismatch_before[2]);
  const double px = 480.0 * 640;
  EXPECT_GT(ghosts(unaligned) / px, 0.05);
  EXPECT_LT(ghosts(b) / px, 0.01);
  EXPECT_EQ(r.rotation_deg[0], 0.0);  // the other bracket was not turned
}

// A bracket of another scene entirely (shot elsewhere): no motion makes it agree, so the
// automatic mode leaves it where it is (the merge flags it as ghost).
TEST(Alignment, ABracketOfAnotherSceneIsNotMoved) {
  TexturedShoot s = blob_shoot(240, 320, 11);
  s.images[0] = blob_shoot(240, 320, 12).images[0];
  BracketSet b = make_brackets(s.images, s.e);
  const AlignmentResult r = align_brackets(b, Alignment::automatic);
  EXPECT_EQ(r.shifts[0], cv::Point(0, 0));
  EXPECT_EQ(r.rotation_deg[0], 0.0);
}

// A smooth, noisy scene: the threshold bitmaps are mostly noise and MTB may report a shift, but
// it does not make them agree better, so the automatic mode keeps the frame.
// Brackets white almost everywhere (the long end of a sunny bracket set): no bitmap to compare,
// so whatever MTB reports for them, they stay.
TEST(Alignment, ABracketWithNothingToCompareIsNotMoved) {
  const TexturedShoot s = textured_shoot();
  testing::BracketCamera cam;
  cam.max_code = 255;
  cam.response = [](int, double X) { return std::pow(X, 1 / 2.2); };
  const std::vector<double> e = {0.1, 0.25, 0.6, 40, 120};
  BracketSet b = make_brackets(testing::synthesize(s.L, e, cam, 5), e);
  const AlignmentResult r = align_brackets(b, Alignment::automatic);
  EXPECT_EQ(r.shifts[3], cv::Point(0, 0));
  EXPECT_EQ(r.shifts[4], cv::Point(0, 0));
}

TEST(Alignment, NoiseAloneNeverMovesABracket) {
  int reported = 0;
  for (unsigned seed = 1; seed <= 6; ++seed) {
    cv::Mat L(96, 128, CV_64FC3);
    for (int r = 0; r < L.rows; ++r)
      for (int x = 0; x < L.cols; ++x) L.at<cv::Vec3d>(r, x) = cv::Vec3d::all(1.0 + 0.002 * x);
    testing::BracketCamera cam;
    cam.max_code = 255;
    cam.full_well = 300;  // a few hundred electrons: noise of several codes
    cam.response = [](int, double X) { return std::pow(X, 1 / 2.2); };
    const std::vector<double> e = {0.1, 0.25, 0.6};
    BracketSet b = make_brackets(testing::synthesize(L, e, cam, seed), e);
    const AlignmentResult r = align_brackets(b, Alignment::automatic);
    for (std::size_t j = 0; j < 3; ++j) {
      EXPECT_EQ(r.shifts[j], cv::Point(0, 0)) << seed;
      reported += r.found[j] != cv::Point(0, 0);
    }
  }
  EXPECT_GT(reported, 0) << "MTB never reported a shift: the test does not exercise the acceptance rule";
}

TEST(Alignment, OffMovesNothingAndOnMovesWhatMtbFinds) {
  TexturedShoot s = textured_shoot();
  s.images[0] = moved(s.images[0], -2, 1);
  BracketSet off = make_brackets(s.images, s.e), on = make_brackets(s.images, s.e);
  EXPECT_EQ(align_brackets(off, Alignment::off).shifts[0], cv::Point(0, 0));
  EXPECT_EQ(align_brackets(on, Alignment::always).shifts[0], cv::Point(2, -1));
  EXPECT_EQ(parse_alignment("auto"), Alignment::automatic);
  EXPECT_THROW(parse_alignment("yes"), std::invalid_argument);
}

// Hand-cropped brackets: files 2 px and 3 px smaller than the middle one, cropped off-centre.
// Loaded with fit_sizes they are centred, padded and registered; the merge matches the truth in
// the interior; without fit_sizes, or beyond 10% a side, the sizes are an error naming the file.
TEST(Alignment, HandCroppedBracketsOfDifferentSizesAreRegisteredOnTheMiddleOne) {
  testing::TempDir dir;
  const TexturedShoot s = textured_shoot();
  PhotoView v;
  v.name = "v";
  const cv::Rect crops[3] = {cv::Rect(2, 0, 157, 127), cv::Rect(0, 0, 160, 128), cv::Rect(0, 3, 158, 124)};
  for (int j = 0; j < 3; ++j) {
    cv::Mat bgr;
    cv::cvtColor(s.images[std::size_t(j)](crops[j]), bgr, cv::COLOR_RGB2BGR);
    bgr.convertTo(bgr, CV_8U);
    const std::string f = dir.file("b" + std::to_string(j) + ".png");
    ASSERT_TRUE(rsibr::write_image(f, bgr));
    v.brackets.push_back({f, s.e[std::size_t(j)] * 0.01, 100.0, 1.0});
  }
  try {
    load_brackets(v);
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("b0.png"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("align"), std::string::npos) << e.what();
  }
  BracketSet b = load_brackets(v, true);
  EXPECT_TRUE(b.fitted_sizes);
  EXPECT_EQ(b.file_sizes[0], cv::Size(157, 127));
  EXPECT_EQ(b.cols(), 160);
  EXPECT_EQ(b.rows(), 128);
  align_brackets(b, Alignment::automatic);
  const MergedImage m = merge_brackets(b, gamma_curve(), NoiseModel{});
  const double unit = m.radiance.at<cv::Vec3f>(64, 80)[1] / s.L.at<cv::Vec3d>(64, 80)[1];
  int bad = 0, n = 0;
  for (int y = 8; y < 120; ++y)
    for (int x = 8; x < 152; ++x, ++n) {
      const double ratio = m.radiance.at<cv::Vec3f>(y, x)[1] / (unit * s.L.at<cv::Vec3d>(y, x)[1]);
      bad += std::abs(ratio - 1) > 0.1;
    }
  EXPECT_LT(bad, n / 200);
  EXPECT_LT(m.ghost, long(0.005 * 160 * 128));
  // More than 10% smaller: not the same framing.
  const cv::Mat small = s.images[0](cv::Rect(0, 0, 120, 128)).clone();
  cv::Mat bgr;
  cv::cvtColor(small, bgr, cv::COLOR_RGB2BGR);
  bgr.convertTo(bgr, CV_8U);
  rsibr::write_image(dir.file("b0.png"), bgr);
  EXPECT_THROW(load_brackets(v, true), std::runtime_error);
}

TEST(MergedExr, RoundTripKeepsChannelsFlagsAndProvenance) {
  testing::TempDir dir;
  MergedImage m;
  m.radiance = cv::Mat(3, 4, CV_32FC3, cv::Scalar(1e6f, 0.5f, 2.f));  // a sun beyond half range
  m.variance = cv::Mat(3, 4, CV_32FC3, cv::Scalar(1.f, 2.f, 3.f));
  m.flags = cv::Mat(3, 4, CV_8UC1, cv::Scalar(0));
  m.flags.at<unsigned char>(1, 2) = kClipped | kGhost;
  write_merged_exr(dir.file("v.exr"), m, {{"responseModel", "gamma"}, {"exposures", "0.01 0.1"}});
  std::map<std::string, std::string> attrs;
  const MergedImage back = read_merged_exr(dir.file("v.exr"), &attrs);
  EXPECT_EQ(attrs["responseModel"], "gamma");
  EXPECT_EQ(attrs["exposures"], "0.01 0.1");
  EXPECT_EQ(back.radiance.at<cv::Vec3f>(2, 3), cv::Vec3f(1e6f, 0.5f, 2.f));
  EXPECT_EQ(back.variance.at<cv::Vec3f>(0, 0), cv::Vec3f(1.f, 2.f, 3.f));
  EXPECT_EQ(back.flags.at<unsigned char>(1, 2), kClipped | kGhost);
  EXPECT_EQ(back.clipped, 1);
  EXPECT_EQ(back.ghost, 1);
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"v.exr"});  // no temporaries
  // Without the variance (as calibration reads a view): the same radiance and flags, no variance.
  const MergedImage lean = read_merged_exr(ExrFileIn(dir.file("v.exr")), nullptr, false);
  EXPECT_TRUE(lean.variance.empty());
  EXPECT_EQ(cv::norm(lean.radiance, back.radiance, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::countNonZero(lean.flags != back.flags), 0);
  EXPECT_EQ(lean.clipped, 1);
  EXPECT_EQ(lean.ghost, 1);
}

TEST(MergedExr, LongAttributeNameIsAnErrorAndWritesNothing) {
  testing::TempDir dir;
  MergedImage m;
  m.radiance = cv::Mat(2, 2, CV_32FC3, cv::Scalar::all(1));
  m.variance = m.radiance.clone();
  m.flags = cv::Mat(2, 2, CV_8UC1, cv::Scalar(0));
  EXPECT_THROW(write_merged_exr(dir.file("v.exr"), m, {{"aVeryLongAttributeNameThatBreaksReaders", "x"}}),
               std::runtime_error);
  EXPECT_TRUE(dir.entries().empty());
}

}  // namespace
}  // namespace rsibr
