// The double-indirection warp (screen table + parametric table, rotations about an axis as offsets)
// against the exact per-texel warp.
#include "runtime/double_indirection_warp.h"

#include "analytic_map_set.h"
#include "warp_error.h"
#include "runtime/blend.h"
#include "runtime/make_warp.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>
#include <cstdio>

namespace rsibr {
namespace {

// A ring of views around world up (0, 1, 0) at elevation `elev_deg`, `count` views.
std::vector<Mat3> ring_frames(int count, double elev_deg, double phase_deg = 0) {
  std::vector<Mat3> out;
  const double e = elev_deg * kPi / 180;
  for (int k = 0; k < count; ++k) {
    const double a = (phase_deg + 360.0 * k / count) * kPi / 180;
    out.push_back(world_from_view_for(Vec3(std::cos(e) * std::sin(a), std::sin(e), std::cos(e) * std::cos(a))));
  }
  return out;
}

Vec3 up_in_view(const Mat3& world_from_view) { return world_from_view.transpose() * Vec3(0, 1, 0); }

// General rotations: a source about 35 degrees from the destination, in random directions.
std::vector<Mat3> general_rotations(int count) {
  std::vector<Mat3> out;
  for (const Vec3& v : testing::random_directions(count, 23)) {
    const Mat3 Td = world_from_view_for(v);
    const Vec3 s = (v + 0.6 * testing::random_directions(1, unsigned(out.size()) + 5)[0]).normalized();
    out.push_back(world_from_view_for(s).transpose() * Td);
  }
  return out;
}

TEST(DoubleIndirectionWarp, AtTableNodesItIsTheExactWarpOfTheNodeDirection) {
  DoubleIndirectionOptions o;
  o.axis = Vec3(0.2, 0.9, -0.3).normalized();
  o.longitudes = 48;
  o.latitudes = 25;
  const DoubleIndirectionWarp warp(64, 64, o);
  std::vector<Mat3> ms;
  for (double deg : {0.0, 7.5, 90.0, 180.0, -133.0})
    ms.push_back(Eigen::AngleAxisd(deg * kPi / 180, o.axis.normalized()).toRotationMatrix());
  for (const Mat3& m : general_rotations(3)) ms.push_back(m);
  for (CentralDirection kind : {CentralDirection::Mirror, CentralDirection::Normal})
    for (const Mat3& m : ms) {
      // The address whose offset lands on node (i, j): lon_i - delta, delta the twist of m about the axis.
      double worst = 0;
      for (int j = 0; j < o.latitudes; ++j)
        for (int i = 0; i < o.longitudes; ++i) {
          const double lon = 2 * kPi * i / o.longitudes - warp.twist(m), lat = kPi * j / (o.latitudes - 1);
          const WarpSample got = warp.lookup(kind, m, lon, lat);
          const WarpSample want = warp_direction(kind, m * warp.direction(lon, lat));
          worst = std::max({worst, (got.disc - want.disc).norm(), std::abs(got.rim - want.rim)});
        }
      EXPECT_LT(worst, 1e-6) << to_string(kind);  // the table holds float32
    }
}

TEST(DoubleIndirectionWarp, AddressesRoundTripThroughDirections) {
  DoubleIndirectionOptions o;
  o.axis = Vec3(-0.4, 0.1, 0.8);
  const DoubleIndirectionWarp warp(32, 32, o);
  for (const Vec3& d : testing::random_directions(200, 3)) {
    const auto [lon, lat] = warp.address(d);
    EXPECT_GE(lon, 0);
    EXPECT_LT(lon, 2 * kPi);
    EXPECT_GE(lat, 0);
    EXPECT_LE(lat, kPi);
    EXPECT_LT((warp.direction(lon, lat) - d).norm(), 1e-12);
  }
  EXPECT_NEAR(warp.address(o.axis.normalized()).second, 0.0, 1e-7);
  EXPECT_NEAR(warp.address(-o.axis.normalized()).second, kPi, 1e-7);
}

TEST(DoubleIndirectionWarp, ARotationAboutTheAxisIsAnOffsetAndBuildsNoTable) {
  const int n = 128;
  const std::vector<Mat3> ring = ring_frames(12, 25);
  DoubleIndirectionOptions o;
  o.axis = up_in_view(ring[0]);
  const DoubleIndirectionWarp warp(n, n, o);
  for (std::size_t s = 1; s < ring.size(); ++s) {
    const Mat3 m = ring[s].transpose() * ring[0];
    EXPECT_TRUE(warp.offset_only(m));
    EXPECT_EQ(testing::compare_to_exact(warp, CentralDirection::Mirror, m, n, 0.2).bad, 0);
  }
  EXPECT_EQ(warp.tables_built(), 0);
  const Mat3 general = general_rotations(1)[0];
  EXPECT_FALSE(warp.offset_only(general));
  EXPECT_EQ(testing::compare_to_exact(warp, CentralDirection::Mirror, general, n, 0.2).bad, 0);
  EXPECT_EQ(testing::compare_to_exact(warp, CentralDirection::Mirror, general, n, 0.2).bad, 0);  // reuses the table
  EXPECT_EQ(warp.tables_built(), 1);
}

TEST(DoubleIndirectionWarp, WithinItsResamplingErrorOfTheExactWarpForRingsAndGeneralRotations) {
  const int n = 256;
  const std::vector<Mat3> ring = ring_frames(10, 20, 3);
  DoubleIndirectionOptions o;
  o.axis = up_in_view(ring[0]);
  const DoubleIndirectionWarp warp(n, n, o);
  std::vector<std::pair<std::string, Mat3>> cases;
  for (std::size_t s = 1; s < 4; ++s) cases.push_back({"ring", ring[s].transpose() * ring[0]});
  for (const Mat3& m : general_rotations(4)) cases.push_back({"general", m});
  for (CentralDirection kind : {CentralDirection::Mirror, CentralDirection::Normal})
    for (const auto& [what, m] : cases) {
      const testing::WarpError e = testing::compare_to_exact(warp, kind, m, n, 0.1);
      EXPECT_EQ(e.bad, 0);
      std::printf("  %s %s: max %.3f, rms %.4f source texels over %ld texels, %d exact cells\n", to_string(kind),
                  what.c_str(), e.max_texels, e.rms_texels, e.texels, warp.exact_cells(kind, m));
      EXPECT_GT(e.texels, 1000);
      EXPECT_LT(e.max_texels, 0.15) << to_string(kind) << " " << what;
      EXPECT_LT(e.rms_texels, 0.02) << to_string(kind) << " " << what;
    }
}

TEST(DoubleIndirectionWarp, ALargerTableHasASmallerError) {
  const int n = 128;
  const Mat3 m = general_rotations(2)[1];
  for (CentralDirection kind : {CentralDirection::Mirror, CentralDirection::Normal}) {
    double previous = INFINITY;
    for (int columns : {32, 64, 128, 256}) {
      DoubleIndirectionOptions o;
      o.longitudes = columns;
      o.latitudes = columns / 2 + 1;
      o.max_spread = 1;  // interpolate wherever the singularity allows, so that coarse tables are measured too
      const testing::WarpError e = testing::compare_to_exact(DoubleIndirectionWarp(n, n, o), kind, m, n, 0.1);
      EXPECT_EQ(e.bad, 0);
      EXPECT_LT(e.rms_texels, previous) << to_string(kind) << " " << columns;
      previous = e.rms_texels;
    }
  }
}

TEST(DoubleIndirectionWarp, NoNaNAtTheSingularityThePolesOrTheLongitudeSeam) {
  const int n = 96;
  std::vector<std::pair<Vec3, Mat3>> cases;
  const Vec3 up(0, 1, 0);
  for (const Vec3& axis : {Vec3(0, 1, 0), Vec3(0, 0, 1), Vec3(0, 0, -1), Vec3(1, 0, 0)}) {
    // Half a turn about the axis (the destination centre lands on the source's singularity for a
    // perpendicular axis), a hair either side of the seam, the identity.
    for (double deg : {180.0, 1e-12, -1e-12, 360.0 - 1e-9, 0.0})
      cases.push_back({axis, Eigen::AngleAxisd(deg * kPi / 180, axis).toRotationMatrix()});
    cases.push_back({axis, Eigen::AngleAxisd(kPi, Vec3(1, 1, 0).normalized()).toRotationMatrix()});
  }
  for (const auto& [axis, m] : cases) {
    DoubleIndirectionOptions o;
    o.axis = axis;
    const DoubleIndirectionWarp warp(n, n, o);
    for (CentralDirection kind : {CentralDirection::Mirror, CentralDirection::Normal}) {
      const testing::WarpError e = testing::compare_to_exact(warp, kind, m, n, 0.1);
      EXPECT_EQ(e.bad, 0);  // every sample finite and in the disc
      EXPECT_LT(e.max_texels, 1.0);
    }
  }
}

// A blend over views of two rings around world up, to a destination on one of them: the sources on
// its ring are offsets into the shared table, the other is a swing table.
TEST(DoubleIndirectionWarp, ABlendMatchesTheExactBlendWithinTheResamplingError) {
  const int n = 128;
  std::vector<Vec3> views;
  for (double elev : {-30.0, 30.0})
    for (const Mat3& T : ring_frames(8, elev, elev > 0 ? 22.5 : 0)) views.push_back(T.col(2));
  views.push_back(Vec3(0, 1, 0));
  views.push_back(Vec3(0, -1, 0));
  const ViewSet set_views(views);
  const MapSet set = testing::analytic_map_set(set_views, n, n, "mirror", testing::mirror_texel);
  const Vec3 dest = ring_frames(16, 30, 7)[3].col(2);
  BlendOptions exact_o;
  exact_o.width = exact_o.height = n;
  const BlendResult exact = blend(set, set_views, dest, Vec3(0, 1, 0), exact_o);
  const auto warp = make_warp({"double-indirection", 16, axis_in_views(set, Vec3(0, 1, 0))}, n, n);
  BlendOptions di_o = exact_o;
  di_o.warp = warp.get();
  const BlendResult di = blend(set, set_views, dest, Vec3(0, 1, 0), di_o);
  double worst = 0, sum = 0;
  long count = 0;
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c) {
      const cv::Vec3f a = di.rgb.at<cv::Vec3f>(r, c), b = exact.rgb.at<cv::Vec3f>(r, c);
      for (int k = 0; k < 3; ++k) {
        ASSERT_TRUE(std::isfinite(a[k]));
        const double d = std::abs(double(a[k]) - double(b[k]));
        worst = std::max(worst, d);
        sum += d * d;
        ++count;
      }
    }
  const double rms = std::sqrt(sum / count);
  std::printf("  blend against the exact blend: max %.2e, rms %.2e (radiance ~0.5-1)\n", worst, rms);
  EXPECT_LT(rms, 5e-4);
  EXPECT_LT(worst, 5e-3);
}

TEST(DoubleIndirectionWarp, BadSettingsAndAnotherSizeAreRefused) {
  EXPECT_THROW(DoubleIndirectionWarp(0, 8), std::invalid_argument);
  DoubleIndirectionOptions o;
  o.axis = Vec3::Zero();
  EXPECT_THROW(DoubleIndirectionWarp(8, 8, o), std::invalid_argument);
  o.axis = Vec3(NAN, 0, 1);
  EXPECT_THROW(DoubleIndirectionWarp(8, 8, o), std::invalid_argument);
  o = {};
  o.longitudes = 2;
  EXPECT_THROW(DoubleIndirectionWarp(8, 8, o), std::invalid_argument);
  o.longitudes = 8192;  // refused before anything is allocated
  o.latitudes = 4097;
  EXPECT_THROW(DoubleIndirectionWarp(8, 8, o), std::invalid_argument);
  EXPECT_STREQ(make_warp({"double-indirection", 16, Vec3(0, 1, 0), 3}, 8, 8)->name(), "double-indirection");
  const DoubleIndirectionWarp warp(8, 8);
  EXPECT_FALSE(warp.supports(16, 16));
  std::vector<WarpSample> out(16);
  EXPECT_THROW(warp.warp_row(CentralDirection::Mirror, Mat3::Identity(), 16, 16, 8, 0, 16, out.data()),
               std::invalid_argument);
}

TEST(MakeWarp, EveryNameGivesThatWarpAndAnUnknownOneListsThem) {
  for (const char* name : {"exact", "precomputed", "tessellated", "double-indirection"}) {
    EXPECT_TRUE(is_warp_name(name));
    const auto w = make_warp({name}, 32, 32);
    EXPECT_STREQ(w->name(), name);
    EXPECT_TRUE(w->supports(32, 32));
  }
  EXPECT_FALSE(is_warp_name("fancy"));
  try {
    make_warp({"fancy"}, 32, 32);
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("double-indirection"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("'fancy'"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace rsibr
