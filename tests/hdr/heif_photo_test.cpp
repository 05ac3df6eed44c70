// HEIF/HEIC photos (formats/heif_image.h, hdr/photo_exif.h): a photo written by libheif with an Exif
// block reads back as the JPEG path would give it, pixels (within the HEVC coding error) and EXIF
// (exposure time, ISO, f-number, camera, focal lengths) alike; a file that is not HEIF is an error
// naming it. The photo is encoded here with libheif's HEVC encoder (skipped where it has none).
#include "formats/heif_image.h"
#include "formats/image_codecs.h"
#include "hdr/exposure_metadata.h"
#include "hdr/photo_exif.h"

#include <gtest/gtest.h>
#include <libheif/heif.h>
#include <opencv2/imgproc.hpp>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <fstream>

namespace rsibr {
namespace {

namespace fs = std::filesystem;

// Writes `rgb` (CV_8UC3, RGB order) as HEIC with the EXIF `exif`; false when libheif has no HEVC
// encoder.
bool write_heic(const fs::path& path, const cv::Mat& rgb, const Exiv2::ExifData& exif) {
  heif_context* ctx = heif_context_alloc();
  heif_encoder* enc = nullptr;
  if (heif_context_get_encoder_for_format(ctx, heif_compression_HEVC, &enc).code != heif_error_Ok) {
    heif_context_free(ctx);
    return false;
  }
  heif_encoder_set_lossy_quality(enc, 95);
  heif_image* img = nullptr;
  heif_image_create(rgb.cols, rgb.rows, heif_colorspace_RGB, heif_chroma_interleaved_RGB, &img);
  heif_image_add_plane(img, heif_channel_interleaved, rgb.cols, rgb.rows, 8);
  int stride = 0;
  uint8_t* p = heif_image_get_plane(img, heif_channel_interleaved, &stride);
  for (int y = 0; y < rgb.rows; ++y) std::memcpy(p + y * stride, rgb.ptr(y), std::size_t(3 * rgb.cols));
  heif_image_handle* handle = nullptr;
  EXPECT_EQ(heif_context_encode_image(ctx, img, enc, nullptr, &handle).code, heif_error_Ok);
  Exiv2::Blob blob;
  Exiv2::ExifParser::encode(blob, Exiv2::littleEndian, exif);
  EXPECT_EQ(heif_context_add_exif_metadata(ctx, handle, blob.data(), int(blob.size())).code, heif_error_Ok);
  EXPECT_EQ(heif_context_write_to_file(ctx, path.c_str()).code, heif_error_Ok);
  heif_image_handle_release(handle);
  heif_image_release(img);
  heif_encoder_release(enc);
  heif_context_free(ctx);
  return true;
}

TEST(HeifPhoto, PixelsAndExifReadBackAsFromAJpeg) {
  const fs::path dir = fs::temp_directory_path() / ("rsibr-heif-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const fs::path file = dir / "IMG_0001.HEIC";
  cv::Mat rgb(48, 64, CV_8UC3);
  for (int y = 0; y < rgb.rows; ++y)
    for (int x = 0; x < rgb.cols; ++x) rgb.at<cv::Vec3b>(y, x) = cv::Vec3b(uchar(4 * x), uchar(5 * y), 128);
  Exiv2::ExifData exif;
  exif["Exif.Image.Make"] = "Apple";
  exif["Exif.Image.Model"] = "iPhone 12";
  exif["Exif.Photo.ExposureTime"] = Exiv2::URational(1, 125);
  exif["Exif.Photo.ISOSpeedRatings"] = uint16_t(200);
  exif["Exif.Photo.FNumber"] = Exiv2::URational(8, 5);
  exif["Exif.Photo.FocalLength"] = Exiv2::URational(42, 10);
  exif["Exif.Photo.FocalLengthIn35mmFilm"] = uint16_t(26);
  if (!write_heic(file, rgb, exif)) GTEST_SKIP() << "libheif has no HEVC encoder here";

  ASSERT_TRUE(is_heif_file(file));
  const cv::Mat bgr = read_image(file.string(), cv::IMREAD_UNCHANGED | cv::IMREAD_ANYDEPTH);
  ASSERT_EQ(bgr.type(), CV_8UC3);
  ASSERT_EQ(bgr.size(), rgb.size());
  cv::Mat back;
  cv::cvtColor(bgr, back, cv::COLOR_BGR2RGB);
  EXPECT_LT(cv::norm(back, rgb, cv::NORM_L1) / double(rgb.total() * 3), 3.0);  // HEVC at quality 95

  BracketPhoto b;
  b.file = file;
  const ResolvedExposure r = resolve_exposure(b);
  EXPECT_DOUBLE_EQ(r.exposure_s, 1.0 / 125);
  EXPECT_DOUBLE_EQ(r.iso, 200);
  EXPECT_DOUBLE_EQ(r.aperture, 1.6);
  EXPECT_EQ(r.source, "exif");
  const Exiv2::ExifData e = read_photo_exif(file.string());
  EXPECT_EQ(e.findKey(Exiv2::ExifKey("Exif.Image.Model"))->toString(), "iPhone 12");
  EXPECT_EQ(e.findKey(Exiv2::ExifKey("Exif.Photo.FocalLengthIn35mmFilm"))->toLong(), 26);
  fs::remove_all(dir);
}

TEST(HeifPhoto, AFileThatIsNotHeifIsAnErrorNamingIt) {
  const fs::path file = fs::temp_directory_path() / ("rsibr-not-" + std::to_string(::getpid()) + ".heic");
  std::ofstream(file) << "this is no HEIF container";
  try {
    read_heif_image(file);
    FAIL() << "a text file was read as HEIF";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(file.string() + ": not a readable HEIF file"), std::string::npos) << e.what();
  }
  fs::remove(file);
}

}  // namespace
}  // namespace rsibr
