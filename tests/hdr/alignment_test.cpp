// Small-shift alignment (OpenCV's median threshold bitmap) and the merged EXR file.
#include "hdr/alignment.h"
#include "hdr/bracket_synth.h"
#include "hdr/merged_exr.h"

#include "core/test_data.h"

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
  const auto shifts = align_brackets(b);
  EXPECT_EQ(shifts[1], cv::Point(0, 0));
  EXPECT_EQ(shifts[0], cv::Point(0, 0));
  EXPECT_EQ(shifts[2], cv::Point(-3, 2));
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
