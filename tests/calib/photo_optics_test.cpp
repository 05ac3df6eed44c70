// The lens from the photos' metadata (calib/lens/photo_optics.h): EXIF focal lengths, lensfun's crop
// factors, and the pinhole they give with its stated uncertainty.
#include "calib/lens/photo_optics.h"

#include "capture/synth_capture.h"
#include "capture/synth_cases.h"
#include "core/test_data.h"
#include "formats/image_codecs.h"

#include <exiv2/exiv2.hpp>
#include <gtest/gtest.h>

#include <cmath>
#include <optional>
#include <string>

namespace rsibr {
namespace {

TEST(PhotoOptics, TheThirtyFiveMillimetreEquivalentGivesTheFocalOnTheDiagonal) {
  PhotoOptics o;
  o.focal_35mm = 50;
  const auto p = pinhole_from_optics(o, 6000, 4000);
  ASSERT_TRUE(p);
  EXPECT_NEAR(p->focal_px, 50 * std::hypot(6000.0, 4000.0) / std::hypot(36.0, 24.0), 1e-9);
  EXPECT_EQ(p->lens.name(), "LENSMODEL_PINHOLE");
  EXPECT_NEAR(p->lens.intrinsics()[0], p->focal_px, 1e-9);
  // 3:2: the diagonal and width conventions agree; rounding and focus remain.
  EXPECT_NEAR(p->sigma_relative, std::hypot(0.29 / 50, 0.03), 1e-12);
  // 4:3 (a phone): the two conventions differ by 4%, half of it is stated.
  const auto q = pinhole_from_optics(o, 4000, 3000);
  ASSERT_TRUE(q);
  const double gap = 36.0 * 5000 / (4000 * std::hypot(36.0, 24.0)) - 1;
  EXPECT_NEAR(q->sigma_relative, std::sqrt(std::pow(0.29 / 50, 2) + std::pow(0.5 * gap, 2) + 0.03 * 0.03), 1e-12);
  EXPECT_GT(q->sigma_relative, p->sigma_relative);
}

TEST(PhotoOptics, FocalLengthNeedsACropFactorAndNothingGivesNothing) {
  PhotoOptics o;
  o.focal_mm = 35;
  EXPECT_FALSE(pinhole_from_optics(o, 6000, 4000));  // the sensor's size unknown
  o.crop_factor = 1.5;
  o.crop_camera = "Nikon D7000";
  const auto p = pinhole_from_optics(o, 6000, 4000);
  ASSERT_TRUE(p);
  EXPECT_NEAR(p->focal_px, 52.5 * std::hypot(6000.0, 4000.0) / std::hypot(36.0, 24.0), 1e-9);
  EXPECT_NE(p->source.find("lensfun"), std::string::npos);
  EXPECT_FALSE(pinhole_from_optics(PhotoOptics{}, 640, 480));
  EXPECT_THROW(pinhole_from_optics(o, 0, 480), std::invalid_argument);
}

// A small JPEG with a Canon camera's EXIF: Model, LensModel (when not empty), FocalLength, FNumber.
void canon_jpeg(const std::string& file, const std::string& model, const std::string& lens, Exiv2::URational focal,
                std::optional<Exiv2::URational> fnumber) {
  rsibr::write_image(file, cv::Mat(40, 60, CV_8UC3, cv::Scalar::all(90)));
  auto image = Exiv2::ImageFactory::open(file);
  image->readMetadata();
  Exiv2::ExifData& exif = image->exifData();
  exif["Exif.Image.Make"] = "Canon";
  exif["Exif.Image.Model"] = model;
  if (!lens.empty()) exif["Exif.Photo.LensModel"] = lens;
  exif["Exif.Photo.FocalLength"] = focal;
  if (fnumber) exif["Exif.Photo.FNumber"] = *fnumber;
  image->writeMetadata();
}

// A real camera's EXIF (make, model, focal length, no 35 mm equivalent): lensfun knows the camera.
TEST(PhotoOptics, LensfunGivesTheCropFactorOfAKnownCamera) {
  testing::TempDir dir;
  canon_jpeg(dir.file("a.jpg"), "Canon EOS 550D", "", {35, 1}, std::nullopt);
  const PhotoOptics o = read_photo_optics(dir.path() / "a.jpg");
  EXPECT_EQ(o.make, "Canon");
  ASSERT_TRUE(o.focal_mm);
  EXPECT_DOUBLE_EQ(*o.focal_mm, 35);
  EXPECT_FALSE(o.focal_35mm);
  ASSERT_TRUE(o.crop_factor) << "lensfun's database (liblensfun-data-v1) has the Canon EOS 550D";
  EXPECT_NEAR(*o.crop_factor, 1.613, 1e-3);
  ASSERT_TRUE(pinhole_from_optics(o, 60, 40));
  // A photo without metadata: nothing, and no error.
  rsibr::write_image(dir.file("plain.png"), cv::Mat(8, 8, CV_8UC3, cv::Scalar::all(1)));
  const PhotoOptics none = read_photo_optics(dir.path() / "plain.png");
  EXPECT_FALSE(none.focal_mm);
  EXPECT_FALSE(none.crop_factor);
}

// A real camera's EXIF naming a lens lensfun profiles: the lens is the profile (distortion
// included), its focal length the EXIF's times the camera's crop factor, with the stated sigma;
// a lens it does not know, or no focal length, leaves it to the pinhole and says why.
TEST(PhotoOptics, ALensLensfunProfilesGivesItsDistortedModel) {
  testing::TempDir dir;
  const std::string file = dir.file("kit.jpg");
  canon_jpeg(file, "Canon EOS 600D", "Canon EF-S 18-55mm f/3.5-5.6 IS", {18, 1}, Exiv2::URational{8, 1});
  const PhotoOptics o = read_photo_optics(file);
  std::string why;
  const auto l = lensfun_from_optics(o, 648, 432, &why);
  ASSERT_TRUE(l) << why;
  EXPECT_EQ(l->lens.name().rfind("LENSMODEL_OPENCV", 0), 0u) << l->lens.name();
  EXPECT_NEAR(l->focal_px, 18 * 1.613 * std::hypot(648.0, 432.0) / std::hypot(36.0, 24.0), 1e-3);
  EXPECT_NEAR(l->sigma_relative, std::hypot(0.03, 0.005), 1e-12);
  EXPECT_NE(l->source.find("ptlens"), std::string::npos) << l->source;
  // Barrel distortion at 18 mm: the photo's corner is nearer the centre than the pinhole puts it.
  const Vec3 corner_ray = LensModel::pinhole(l->focal_px, 648, 432).unproject(Vec2(0, 0));
  EXPECT_GT(l->lens.project(corner_ray).x(), 1.0);
  PhotoOptics unknown = o;
  unknown.lens = "Acme Wonderlens";
  EXPECT_FALSE(lensfun_from_optics(unknown, 648, 432, &why));
  EXPECT_NE(why.find("does not know the lens"), std::string::npos) << why;
  PhotoOptics no_focal = o;
  no_focal.focal_mm.reset();
  EXPECT_FALSE(lensfun_from_optics(no_focal, 648, 432, &why));
  EXPECT_NE(why.find("FocalLength"), std::string::npos) << why;
}

// A known lens's vignetting from lensfun (a Canon EF 50mm f/1.8 II wide open on a full-frame body):
// the polynomial reproduces lensfun's own correction over the frame, darkens toward the corner, and
// on a full-frame body (crop 1, lensfun's r = 1 at the corner) equals the database's pa terms.
TEST(PhotoOptics, LensfunGivesTheVignettingOfAKnownLens) {
  testing::TempDir dir;
  canon_jpeg(dir.file("a.jpg"), "Canon EOS 5D Mark II", "Canon EF 50mm f/1.8 II", {50, 1}, Exiv2::URational(18, 10));
  const PhotoOptics o = read_photo_optics(dir.path() / "a.jpg");
  ASSERT_TRUE(o.aperture);
  EXPECT_NEAR(*o.aperture, 1.8, 1e-6);
  const auto v = lensfun_vignetting(o, 1500, 1000, 10.0);
  ASSERT_TRUE(v) << "lensfun's database (liblensfun-data-v1) has the EF 50mm f/1.8 II's vignetting";
  EXPECT_NE(v->lens.find("50mm"), std::string::npos) << v->lens;
  EXPECT_LT(v->fit_rms, 0.01);
  const double corner = 1 + v->k[0] + v->k[1] + v->k[2];
  EXPECT_LT(corner, 0.5);  // wide open: more than a stop at the corner
  EXPECT_NEAR(v->k[0], -1.4745, 0.02);
  EXPECT_NEAR(v->k[1], 1.1285, 0.05);
  EXPECT_NEAR(v->k[2], -0.4284, 0.05);
  // A lens lensfun does not know: nothing.
  PhotoOptics unknown = o;
  unknown.lens = "rsibr imaginary 13mm f/0.7";
  EXPECT_FALSE(lensfun_vignetting(unknown, 1500, 1000));
  unknown = o;
  unknown.aperture.reset();
  EXPECT_FALSE(lensfun_vignetting(unknown, 1500, 1000));
}

// The synthetic camera writes the EXIF a camera does; the pinhole it gives is within its stated
// sigma of the true focal length, for two lenses and two framings.
TEST(PhotoOptics, TheSynthesizedPhotosEXIFGivesTheTrueFocalWithinItsStatedSigma) {
  for (const char* camera :
       {", format: jpeg", ", format: png, lens: {model: LENSMODEL_PINHOLE, focal_px: 130}", ", format: dng"}) {
    testing::TempDir dir;
    std::string text = testing::small_scene_text(camera);
    if (std::string(camera).find("focal_px: 130") != std::string::npos) {
      const auto at = text.find("lens: {model: LENSMODEL_PINHOLE, focal_px: 200}, ");
      ASSERT_NE(at, std::string::npos);
      text.erase(at, std::string("lens: {model: LENSMODEL_PINHOLE, focal_px: 200}, ").size());
    }
    const SynthScene scene = parse_synth_scene(text, "small.yaml", ".");
    write_synth_capture(scene, dir.path() / "out");
    const double truth = scene.camera.lens.intrinsics()[0];
    const std::string ext = scene.camera.format == "jpeg" ? "jpg" : scene.camera.format;
    const auto file = dir.path() / "out" / "photos" / "view00" / ("view00_b00." + ext);
    const PhotoOptics o = read_photo_optics(file);
    EXPECT_EQ(o.make, "rsibr");
    ASSERT_TRUE(o.focal_35mm) << camera;
    const auto p = pinhole_from_optics(o, scene.camera.lens.width(), scene.camera.lens.height());
    ASSERT_TRUE(p);
    EXPECT_LT(std::abs(p->focal_px / truth - 1), p->sigma_relative) << camera << ": " << p->focal_px << " vs " << truth;
  }
}

}  // namespace
}  // namespace rsibr
