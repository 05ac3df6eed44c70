// rsibr's +Y-up world and Blender's +Z-up world, and the scene's small tables.
#include "export/blender_axes.h"
#include "export/blender_scene.h"

#include "bake/brdf_spec.h"
#include "core/cell_centred_latlong.h"

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>

namespace rsibr {
namespace {

TEST(BlenderAxes, TheMappingIsAProperRotationTakingUpToUp) {
  const Mat3 p = blender_from_rsibr();
  EXPECT_LT((p * p.transpose() - Mat3::Identity()).norm(), 1e-15);
  EXPECT_DOUBLE_EQ(p.determinant(), 1.0);
  EXPECT_EQ(p * Vec3(0, 1, 0), Vec3(0, 0, 1));  // up
  EXPECT_EQ(p * Vec3(0, 0, 1), Vec3(1, 0, 0));  // longitude 0
  EXPECT_EQ(p * Vec3(1, 0, 0), Vec3(0, 1, 0));  // longitude +pi/2
}

// Blender's Environment Texture reads the world image at u = 0.5 - atan2(y, x) / 2pi,
// v = 0.5 + asin(z) / pi (its own direction (x, y, z)); the image rsibr writes for it is
// cell-centred. So the texel a Blender direction reads is the one rsibr put there for its direction.
TEST(BlenderAxes, BlendersEquirectangularLookupOfAMappedDirectionFindsRsibrsTexel) {
  const int w = 64, h = 32;
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < w; ++i) {
      const Vec3 b = blender_from_rsibr() * cell_centred_latlong_direction(i, j, w, h);
      double u = 0.5 - std::atan2(b.y(), b.x()) / (2 * kPi);
      u -= std::floor(u);
      const double v = 0.5 + std::asin(std::clamp(b.z(), -1.0, 1.0)) / kPi;
      EXPECT_NEAR(std::remainder(u * w - (i + 0.5), double(w)), 0, 1e-6);
      EXPECT_NEAR((1 - v) * h - 1, j - 0.5, 1e-6);
    }
}

// A camera looking along rsibr's -Z with its image's y down along -Y: in Blender it looks along
// -X (its local -Z) with its local +Y (image up) along +Z.
TEST(BlenderAxes, ACameraKeepsWhereItLooksAndWhichWayIsUp) {
  Mat3 world_from_cam;
  world_from_cam.col(0) = Vec3(1, 0, 0);   // x right
  world_from_cam.col(1) = Vec3(0, -1, 0);  // y down
  world_from_cam.col(2) = Vec3(0, 0, -1);  // z forward
  const Mat3 r = blender_camera_rotation(world_from_cam);
  EXPECT_LT((r * Vec3(0, 0, -1) - blender_from_rsibr() * Vec3(0, 0, -1)).norm(), 1e-15);  // forward
  EXPECT_LT((r * Vec3(0, 1, 0) - Vec3(0, 0, 1)).norm(), 1e-15);                           // image up
  EXPECT_LT((r * Vec3(1, 0, 0) - blender_from_rsibr() * Vec3(1, 0, 0)).norm(), 1e-15);    // image right
  EXPECT_NEAR(r.determinant(), 1.0, 1e-15);
}

TEST(BlenderScene, TheFresnelTableHoldsFAtTexelCentres) {
  const std::string spec = "{type: conductor, eta: [2.9, 2.9, 2.6], k: [3.4, 3.4, 3.2]}";
  const auto fresnel = make_fresnel(YAML::Load(spec));
  const std::vector<Vec3> table = fresnel_table(spec, 16);
  ASSERT_EQ(table.size(), 16u);
  for (int k = 0; k < 16; ++k) EXPECT_LT((table[k] - fresnel->eval((k + 0.5) / 16)).norm(), 1e-15) << k;
  EXPECT_GT(table.front().x(), table.back().x());  // a conductor reflects more at grazing angles
}

TEST(BlenderScene, TheScriptIsEmbedded) {
  const std::string script = blender_scene_script();
  EXPECT_NE(script.find("def build(scene_file)"), std::string::npos);
  EXPECT_NE(script.find("rsibr_blender_scene"), std::string::npos);
}

}  // namespace
}  // namespace rsibr
