#include "cluster/distributed_bake.h"

#include "bake/brdf_spec.h"
#include "core/patterns.h"

#include <gtest/gtest.h>

#include <cstring>
#include <stdexcept>

namespace rsibr::cluster {
namespace {

EnvMap sunny_environment() {
  const Radiance sky = patterns::sun_and_sky(Vec3(0.3, 0.6, -0.5), 2.0 * kPi / 180, Vec3::Constant(1e4),
                                             Vec3(0.25, 0.45, 1.0), Vec3(0.9, 0.9, 0.85));
  return render_pattern(sky, Layout(LayoutKind::LatLong, 64, 32), 2);
}

bool same_bytes(const cv::Mat& a, const cv::Mat& b) {
  return a.type() == b.type() && a.size() == b.size() && a.isContinuous() && b.isContinuous() &&
         std::memcmp(a.data, b.data, a.total() * a.elemSize()) == 0;
}

// Every rank of an n-rank bake played in this process: its rows integrated, sent as bytes and placed.
MapSet bake_as_ranks(const Brdf& brdf, const Integrator& integrator, const ViewSet& views,
                     const MapSetBakeOptions& options, int ranks) {
  std::vector<cv::Mat> maps(views.views().size());
  for (cv::Mat& m : maps) m = cv::Mat(options.res, options.res, CV_32FC3, cv::Scalar::all(0));
  for (int k = 0; k < ranks; ++k) {
    const auto spans = rows_of_rank(int(views.views().size()), options.res, k, ranks);
    const auto bytes = integrate_spans(brdf, integrator, views, options, spans);
    place_spans(bytes.data(), bytes.size(), spans, maps);
  }
  return computed_map_set(brdf, integrator, views, options, std::move(maps));
}

TEST(DistributedBake, AnyNumberOfRanksGivesTheSerialBytesForEveryIntegrator) {
  const EnvMap env = sunny_environment();
  const auto ggx = parse_brdf("type: ggx\nroughness: 0.3\nfresnel: {type: schlick, f0: [0.9, 0.7, 0.4]}\n");
  const auto grey = parse_brdf("type: lambert\nalbedo: [0.18, 0.18, 0.18]\n");
  const ViewSet views = ViewSet::named("octa");
  for (const char* method : {"mis", "fis", "reference", "sh"}) {
    const Brdf& brdf = std::string(method) == "sh" ? *grey : *ggx;
    const auto integrator = make_integrator(method, env);
    MapSetBakeOptions options;
    options.res = 13;  // odd: the cuts fall inside maps and rows are uneven
    options.integrator.samples = 4;
    options.integrator.seed = 11;
    options.integrator.reference_width = 16;
    options.normalise_albedo = std::string(method) == "mis";
    const MapSet serial = bake_map_set(brdf, *integrator, views, options);
    for (int ranks : {1, 2, 3, 7, 100}) {
      const MapSet split = bake_as_ranks(brdf, *integrator, views, options, ranks);
      ASSERT_EQ(split.views.size(), serial.views.size());
      for (std::size_t i = 0; i < serial.views.size(); ++i) {
        EXPECT_TRUE(same_bytes(split.views[i].rgb, serial.views[i].rgb))
            << method << ", " << ranks << " ranks, view " << i;
        EXPECT_EQ(split.views[i].attributes, serial.views[i].attributes);
        EXPECT_EQ(split.views[i].albedo, serial.views[i].albedo);
      }
    }
  }
}

TEST(DistributedBake, OneRankSessionIsTheSerialBake) {
  const EnvMap env = sunny_environment();
  const auto grey = parse_brdf("type: lambert\nalbedo: [0.5, 0.4, 0.3]\n");
  const auto integrator = make_integrator("sh", env);
  MapSetBakeOptions options;
  options.res = 8;
  DistributedBakeTimes times;
  const MapSet a =
      bake_map_set_distributed(*grey, *integrator, ViewSet::named("tetra"), options, Session::current(), {}, &times);
  const MapSet b = bake_map_set(*grey, *integrator, ViewSet::named("tetra"), options);
  ASSERT_EQ(a.views.size(), 4u);
  for (std::size_t i = 0; i < a.views.size(); ++i) EXPECT_TRUE(same_bytes(a.views[i].rgb, b.views[i].rgb));
  EXPECT_EQ(times.rows, 4 * 8);
  EXPECT_EQ(Session::current().size(), 1);
}

TEST(DistributedBake, BytesThatAreNotExactlyTheSpansRowsAreAnError) {
  std::vector<cv::Mat> maps{cv::Mat(4, 4, CV_32FC3, cv::Scalar::all(0))};
  const std::vector<RowSpan> spans{{0, 1, 3}};
  const std::vector<std::uint8_t> short_of(2 * 4 * 12 - 1), over(2 * 4 * 12 + 1), exact(2 * 4 * 12, 0);
  EXPECT_THROW(place_spans(short_of.data(), short_of.size(), spans, maps), std::runtime_error);
  EXPECT_THROW(place_spans(over.data(), over.size(), spans, maps), std::runtime_error);
  EXPECT_NO_THROW(place_spans(exact.data(), exact.size(), spans, maps));
}

TEST(DistributedBake, MapsThatDoNotMatchTheViewsAreAnError) {
  const EnvMap env = sunny_environment();
  const auto grey = parse_brdf("type: lambert\nalbedo: [0.5, 0.4, 0.3]\n");
  const auto integrator = make_integrator("sh", env);
  MapSetBakeOptions options;
  options.res = 4;
  EXPECT_THROW(computed_map_set(*grey, *integrator, ViewSet::named("tetra"), options, {}), std::invalid_argument);
  std::vector<cv::Mat> wrong(4, cv::Mat(5, 5, CV_32FC3, cv::Scalar::all(0)));
  EXPECT_THROW(computed_map_set(*grey, *integrator, ViewSet::named("tetra"), options, wrong), std::invalid_argument);
}

}  // namespace
}  // namespace rsibr::cluster
