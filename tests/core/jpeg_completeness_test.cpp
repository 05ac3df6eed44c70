// jpeg_is_complete (formats/image_codecs.h): a JPEG cut short is told from a whole one, whatever
// comes after the end marker or inside the segments before the scan.
#include "formats/image_codecs.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

namespace fs = std::filesystem;
namespace rsibr {
namespace {

using Bytes = std::vector<unsigned char>;

class JpegCompleteness : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("rsibr_jpeg_" + std::to_string(std::random_device{}()));
    fs::create_directories(dir_);
    cv::Mat image(48, 64, CV_8UC3);
    cv::randu(image, 0, 255);  // noise: a scan of many bytes, with 0xFF stuffed in it
    ASSERT_TRUE(encode_image(".jpg", image, jpeg_));
  }
  void TearDown() override { fs::remove_all(dir_); }
  bool complete(const Bytes& bytes) {
    const fs::path p = dir_ / ("f" + std::to_string(n_++) + ".jpg");
    std::ofstream(p, std::ios::binary)
        .write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
    return jpeg_is_complete(p.string());
  }
  Bytes first(std::size_t n) const { return Bytes(jpeg_.begin(), jpeg_.begin() + std::ptrdiff_t(n)); }
  fs::path dir_;
  Bytes jpeg_;
  int n_ = 0;
};

TEST_F(JpegCompleteness, AWholeFileIsCompleteAndEveryCutShortOneIsNot) {
  EXPECT_TRUE(complete(jpeg_));
  for (std::size_t keep :
       {std::size_t(2), std::size_t(20), jpeg_.size() / 3, jpeg_.size() / 2, jpeg_.size() - 2, jpeg_.size() - 1})
    EXPECT_FALSE(complete(first(keep))) << keep << " of " << jpeg_.size() << " bytes";
}

TEST_F(JpegCompleteness, BytesAfterTheEndMarkerAreAllowed) {
  Bytes trailer = jpeg_;
  for (int i = 0; i < 100; ++i) trailer.push_back(static_cast<unsigned char>(i));  // a phone's appended data
  EXPECT_TRUE(complete(trailer));
}

// An Exif thumbnail is a whole JPEG inside an APP1 segment, end marker included: it must not make
// a main image cut short look complete.
TEST_F(JpegCompleteness, AnEndMarkerInsideASegmentBeforeTheScanDoesNotCount) {
  const Bytes thumb = {0xFF, 0xD8, 0x01, 0x02, 0xFF, 0xD9};
  Bytes with_thumb = {0xFF, 0xD8, 0xFF, 0xE1, 0x00, static_cast<unsigned char>(2 + thumb.size())};
  with_thumb.insert(with_thumb.end(), thumb.begin(), thumb.end());
  with_thumb.insert(with_thumb.end(), jpeg_.begin() + 2, jpeg_.end());
  EXPECT_TRUE(complete(with_thumb));
  EXPECT_FALSE(complete(Bytes(with_thumb.begin(), with_thumb.begin() + std::ptrdiff_t(with_thumb.size() / 2))));
}

TEST_F(JpegCompleteness, OtherFilesAreNotCompleteJpegs) {
  cv::Mat image(4, 4, CV_8UC3, cv::Scalar::all(7));
  Bytes png;
  ASSERT_TRUE(encode_image(".png", image, png));
  EXPECT_FALSE(complete(png));
  EXPECT_FALSE(complete({}));
  EXPECT_FALSE(jpeg_is_complete((dir_ / "missing.jpg").string()));
}

// write_image encodes in memory and writes the bytes itself: a file it cannot create is `false`.
TEST_F(JpegCompleteness, WriteImageReportsAFileItCannotWrite) {
  const cv::Mat image(4, 4, CV_8UC3, cv::Scalar::all(7));
  EXPECT_FALSE(write_image((dir_ / "no-such-folder" / "a.jpg").string(), image));
  ASSERT_TRUE(write_image((dir_ / "a.jpg").string(), image));
  EXPECT_TRUE(jpeg_is_complete((dir_ / "a.jpg").string()));
}

}  // namespace
}  // namespace rsibr
