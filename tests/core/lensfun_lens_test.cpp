// Lenses from lensfun's database as mrcal models (core/lensfun_lens.h), checked against lensfun's
// own mapping: each fitted model, through mrcal, must send the ray of every corrected pixel to
// the photo's pixel that lensfun says, for each of lensfun's distortion models (ptlens, poly3,
// poly5), barrel and pincushion, on APS-C and compact cameras.
#include "core/lensfun_lens.h"

#include <gtest/gtest.h>
#include <lensfun/lensfun.h>

#include <cmath>

namespace rsibr {
namespace {

struct Case {
  const char *make, *model, *lens;
  double focal_mm;
  int width, height;
};

// lensfun's mapping, corrected pixel -> photo pixel, straight from its modifier.
struct LensfunMapping {
  lfModifier* mod = nullptr;
  const lfLens** lenses = nullptr;
  const lfCamera** cams = nullptr;
  LensfunMapping(const Case& c) {
    cams = lf_db_find_cameras(lensfun_database(), c.make, c.model);
    lenses = lf_db_find_lenses_hd(lensfun_database(), cams[0], nullptr, c.lens, 0);
    mod = lf_modifier_new(lenses[0], cams[0]->CropFactor, c.width, c.height);
    lf_modifier_initialize(mod, lenses[0], LF_PF_F32, float(c.focal_mm), 8.0f, 1.0f, 1.0f, lenses[0]->Type,
                           LF_MODIFY_DISTORTION, 0);
  }
  ~LensfunMapping() {
    lf_modifier_destroy(mod);
    lf_free(lenses);
    lf_free(cams);
  }
  Vec2 operator()(double x, double y) const {
    alignas(16) float r[2];
    lf_modifier_apply_geometry_distortion(mod, float(x), float(y), 1, 1, r);
    return {r[0], r[1]};
  }
};

// The corrected image is a pinhole image (centre c, some focal f_u): fit f_u to the model's rays
// of lensfun's photo pixels, then measure how far the model is from lensfun, in pixels.
double worst_disagreement_px(const LensfunLens& L, const Case& c, double* corrected_focal = nullptr) {
  const LensfunMapping map(c);
  const Vec2 centre(L.lens.intrinsics()[2], L.lens.intrinsics()[3]);
  std::vector<std::pair<Vec2, Vec2>> pairs;  // (u - centre, ray's z = 1 point)
  for (int j = 0; j <= 30; ++j)
    for (int i = 0; i <= 40; ++i) {
      const Vec2 u(-0.1 * c.width + 1.2 * c.width * i / 40.0, -0.1 * c.height + 1.2 * c.height * j / 30.0);
      const Vec2 d = map(u.x(), u.y());
      if (!L.lens.in_image(d)) continue;
      const Vec3 ray = L.lens.unproject(d);
      pairs.push_back({u - centre, Vec2(ray.x() / ray.z(), ray.y() / ray.z())});
    }
  EXPECT_GT(pairs.size(), 500u);
  double num = 0, den = 0;
  for (const auto& [v, x] : pairs) {
    num += v.dot(x);
    den += x.dot(x);
  }
  const double fu = num / den;
  if (corrected_focal) *corrected_focal = fu;
  double worst = 0;
  for (const auto& [v, x] : pairs) {
    // Back to the photo: lensfun's pixel for the corrected pixel the model's ray points at.
    const Vec2 u = centre + fu * x;
    const Vec2 lensfun = map(u.x(), u.y());
    const Vec2 model = L.lens.project(Vec3(x.x(), x.y(), 1));
    worst = std::max(worst, (lensfun - model).norm());
  }
  return worst;
}

TEST(LensfunLens, TheModelReproducesLensfunsMappingForEveryDistortionModel) {
  const Case cases[] = {
      {"Canon", "Canon EOS 600D", "Canon EF-S 18-55mm f/3.5-5.6 IS", 18, 5184 / 8, 3456 / 8},  // ptlens, barrel
      {"Canon", "Canon EOS 600D", "Canon EF-S 18-55mm f/3.5-5.6 IS", 55, 5184 / 8, 3456 / 8},  // ptlens, pincushion
      {"NIKON CORPORATION", "NIKON D7000", "Nikon AF-S Nikkor 16-35mm f/4G ED VR", 16, 4928 / 8,
       3264 / 8},  // ptlens, strong
      {"NIKON CORPORATION", "NIKON D7000", "Nikon AF-S DX Zoom-Nikkor 17-55mm f/2.8G IF-ED", 17, 4928 / 8,
       3264 / 8},  // poly3
      {"Canon", "Canon PowerShot G12", "Canon PowerShot G12 & compatibles (Standard)", 6.1, 3648 / 8,
       2736 / 8},                                                                     // poly5
      {"Canon", "Canon EOS 600D", "Canon EF-S 18-55mm f/3.5-5.6 IS", 21, 1200, 800},  // between profiles, larger
  };
  for (const Case& c : cases) {
    std::string why;
    const auto L = lensfun_lens(c.make, c.model, c.lens, c.focal_mm, c.width, c.height, &why);
    ASSERT_TRUE(L) << c.lens << " at " << c.focal_mm << " mm: " << why;
    EXPECT_NE(L->profile.find(" at "), std::string::npos) << L->profile;
    const double worst = worst_disagreement_px(*L, c);
    // Measured against lensfun by this test, independently of the fit's own numbers.
    EXPECT_LT(worst, 0.15) << c.lens << " at " << c.focal_mm << " mm (" << L->profile << ", " << L->lens.name() << ")";
    EXPECT_LT(L->fit_max_px, 0.15) << c.lens;
    EXPECT_LT(L->fit_rms_px, 0.05) << c.lens;
    EXPECT_NEAR(L->fit_max_px, worst, 0.05) << c.lens;
  }
}

// The model's fx = fy is the lens's paraxial focal length in pixels: the EXIF focal length times
// the camera's crop factor, on the diagonal of the 35 mm frame (lensfun's corrected image has
// another scale: its magnification at the centre is not 1).
TEST(LensfunLens, TheFocalLengthIsTheParaxialOneOfTheNamedCamera) {
  const Case c{"Canon", "Canon EOS 600D", "Canon EF-S 18-55mm f/3.5-5.6 IS", 18, 648, 432};
  const auto L = lensfun_lens(c.make, c.model, c.lens, c.focal_mm, c.width, c.height);
  ASSERT_TRUE(L);
  EXPECT_NEAR(L->crop_factor, 1.613, 1e-3) << "lensfun's crop factor of the EOS 600D";
  const double f = 18 * 1.613 * std::hypot(648.0, 432.0) / std::hypot(36.0, 24.0);
  EXPECT_NEAR(L->focal_px, f, 1e-3 * f);
  EXPECT_DOUBLE_EQ(L->lens.intrinsics()[0], L->focal_px);
  EXPECT_DOUBLE_EQ(L->lens.intrinsics()[1], L->focal_px);
  EXPECT_NEAR(L->lens.intrinsics()[2], 323.5, 1e-6);
  EXPECT_NEAR(L->lens.intrinsics()[3], 215.5, 1e-6);
  // Near the axis the model has scale f; lensfun's corrected image has f / m, m = 1 - a - b - c.
  double fu = 0;
  worst_disagreement_px(*L, c, &fu);
  const double m = 1 - 0.00644 + 0.01245 + 0.0348;
  EXPECT_NEAR(fu, f / m, 2e-3 * f);
  const Vec2 p = L->lens.project(Vec3(1e-4, 0, 1));
  EXPECT_NEAR((p.x() - 323.5) / 1e-4, f, 1e-3 * f);
}

// A profile of no distortion (the EF-S 18-55mm at 35 mm: a = b = c = 0) gives a pinhole.
TEST(LensfunLens, AProfileWithoutDistortionGivesAPinhole) {
  const auto L = lensfun_lens("Canon", "Canon EOS 600D", "Canon EF-S 18-55mm f/3.5-5.6 IS", 35, 648, 432);
  ASSERT_TRUE(L);
  EXPECT_EQ(L->lens.name(), "LENSMODEL_OPENCV5");
  // lensfun's mapping is in single precision: zero to that.
  for (std::size_t i = 4; i < L->lens.intrinsics().size(); ++i) EXPECT_NEAR(L->lens.intrinsics()[i], 0, 1e-4) << i;
  EXPECT_LT(L->fit_max_px, 1e-3);
}

TEST(LensfunLens, UnknownLensesCamerasAndFisheyesSayWhy) {
  std::string why;
  EXPECT_FALSE(lensfun_lens("Canon", "Canon EOS 600D", "Acme Wonderlens 12-400mm", 18, 648, 432, &why));
  EXPECT_NE(why.find("does not know the lens"), std::string::npos) << why;
  EXPECT_FALSE(lensfun_lens("Acme", "Acme One", "Canon EF-S 18-55mm f/3.5-5.6 IS", 18, 648, 432, &why));
  EXPECT_NE(why.find("does not know the camera"), std::string::npos) << why;
  EXPECT_FALSE(lensfun_lens("Canon", "Canon EOS 600D", "", 18, 648, 432, &why));
  EXPECT_NE(why.find("names no lens"), std::string::npos) << why;
  EXPECT_FALSE(
      lensfun_lens("NIKON CORPORATION", "NIKON D7000", "Nikon AI-S Fisheye-Nikkor 6mm f/2.8", 6, 648, 432, &why));
  EXPECT_NE(why.find("not rectilinear"), std::string::npos) << why;
  EXPECT_THROW(lensfun_lens("Canon", "Canon EOS 600D", "Canon EF-S 18-55mm f/3.5-5.6 IS", 0, 648, 432),
               std::invalid_argument);
  EXPECT_THROW(lensfun_lens("Canon", "Canon EOS 600D", "Canon EF-S 18-55mm f/3.5-5.6 IS", 18, 0, 432),
               std::invalid_argument);
}

}  // namespace
}  // namespace rsibr
