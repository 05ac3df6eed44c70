// Exposure metadata (photoset.yaml, EXIF via exiv2) and bracket loading.
#include "hdr/bracket_set.h"

#include "formats/photo_set.h"
#include "core/test_data.h"
#include "formats/image_codecs.h"

#include <exiv2/exiv2.hpp>
#include <gtest/gtest.h>

#include <fstream>

namespace rsibr {
namespace {

void write_exif(const std::string& file, Exiv2::Rational exposure, long iso, Exiv2::Rational fnumber) {
  auto image = Exiv2::ImageFactory::open(file);
  image->readMetadata();
  Exiv2::ExifData& exif = image->exifData();
  exif["Exif.Photo.ExposureTime"] = exposure;
  exif["Exif.Photo.ISOSpeedRatings"] = uint16_t(iso);
  exif["Exif.Photo.FNumber"] = fnumber;
  image->writeMetadata();
}

TEST(ExposureMetadata, ExifFillsWhatTheYamlLeavesOut) {
  testing::TempDir dir;
  const cv::Mat img(8, 8, CV_8UC3, cv::Scalar(10, 20, 30));
  rsibr::write_image(dir.file("a.jpg"), img);
  write_exif(dir.file("a.jpg"), {1, 250}, 400, {8, 1});
  BracketPhoto p;
  p.file = dir.file("a.jpg");
  const ResolvedExposure r = resolve_exposure(p);
  EXPECT_DOUBLE_EQ(r.exposure_s, 1.0 / 250);
  EXPECT_DOUBLE_EQ(r.iso, 400);
  EXPECT_DOUBLE_EQ(r.aperture, 8);
  EXPECT_DOUBLE_EQ(r.relative, (1.0 / 250) * 4 / 64);
  EXPECT_EQ(r.source, "exif");
  // YAML values win; the rest still come from EXIF.
  p.exposure_s = 0.5;
  const ResolvedExposure both = resolve_exposure(p);
  EXPECT_DOUBLE_EQ(both.exposure_s, 0.5);
  EXPECT_DOUBLE_EQ(both.iso, 400);
  EXPECT_EQ(both.source, "yaml+exif");
}

TEST(ExposureMetadata, SixteenBitTiffExifIsRead) {
  testing::TempDir dir;
  rsibr::write_image(dir.file("a.tif"), cv::Mat(8, 8, CV_16UC3, cv::Scalar(1000, 2000, 3000)));
  write_exif(dir.file("a.tif"), {60, 1}, 100, {28, 10});
  BracketPhoto p;
  p.file = dir.file("a.tif");
  EXPECT_DOUBLE_EQ(resolve_exposure(p).exposure_s, 60.0);
  EXPECT_DOUBLE_EQ(resolve_exposure(p).aperture, 2.8);
}

TEST(ExposureMetadata, MissingExposureIsAnErrorNamingTheFile) {
  testing::TempDir dir;
  rsibr::write_image(dir.file("plain.png"), cv::Mat(4, 4, CV_8UC3, cv::Scalar::all(1)));
  BracketPhoto p;
  p.file = dir.file("plain.png");
  try {
    resolve_exposure(p);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("plain.png"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("exposure"), std::string::npos);
  }
}

TEST(BracketSet, LoadsAViewSortedByExposureInRgbOrder) {
  testing::TempDir dir;
  rsibr::write_image(dir.file("long.png"), cv::Mat(6, 5, CV_8UC3, cv::Scalar(30, 20, 10)));  // BGR on disk
  rsibr::write_image(dir.file("short.png"), cv::Mat(6, 5, CV_8UC3, cv::Scalar(3, 2, 1)));
  std::ofstream(dir.file("photoset.yaml")) << "rsibr_photoset: 1\nviews:\n  - name: v\n    brackets:\n"
                                              "      - {file: long.png, exposure_s: 0.1}\n"
                                              "      - {file: short.png, exposure_s: 0.01}\n";
  const PhotoSet set = load_photo_set(dir.path());
  const BracketSet b = load_brackets(set.views[0]);
  ASSERT_EQ(b.size(), 2u);
  EXPECT_EQ(b.max_code, 255);
  EXPECT_DOUBLE_EQ(b.exposures[0], 0.01);
  EXPECT_EQ(b.codes[0].type(), CV_16UC3);
  EXPECT_EQ(b.codes[0].at<cv::Vec3w>(0, 0), cv::Vec3w(1, 2, 3));
  EXPECT_EQ(b.codes[1].at<cv::Vec3w>(0, 0), cv::Vec3w(10, 20, 30));
}

TEST(BracketSet, MismatchedSizesDepthsAndExposuresAreErrors) {
  const cv::Mat a(4, 4, CV_8UC3), b(4, 5, CV_8UC3), c(4, 4, CV_16UC3);
  EXPECT_THROW(make_brackets({a, b}, {1, 2}), std::runtime_error);
  EXPECT_THROW(make_brackets({a, c}, {1, 2}), std::runtime_error);
  EXPECT_THROW(make_brackets({a, a}, {1, 1}), std::runtime_error);
  EXPECT_THROW(make_brackets({a, a}, {1, -1}), std::runtime_error);
  EXPECT_THROW(make_brackets({cv::Mat(4, 4, CV_32FC3)}, {1}), std::runtime_error);
}

TEST(BracketSet, UnreadableImageIsAnErrorNamingIt) {
  testing::TempDir dir;
  std::ofstream(dir.file("junk.png")) << "not a png";
  std::ofstream(dir.file("photoset.yaml")) << "rsibr_photoset: 1\nviews:\n  - name: v\n    brackets:\n"
                                              "      - {file: junk.png, exposure_s: 0.1}\n";
  try {
    load_brackets(load_photo_set(dir.path()).views[0]);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("junk.png"), std::string::npos);
  }
}

}  // namespace
}  // namespace rsibr
