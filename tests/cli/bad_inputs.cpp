// Writes the hostile files of the bad-input battery (tests/cli/bad_input_battery.sh) that a shell
// cannot make: environments and map sets whose pixels hold NaN, +-Inf, FLT_MAX, negative values or
// confidences outside [0, 1], and degenerate but well-formed shapes (1x1 maps, one view, two views
// with one direction). Usage: rsibr_bad_inputs FOLDER
#include "formats/exr_io.h"
#include "formats/map_set.h"
#include "core/vec.h"
#include "core/view_set.h"

#include <cfloat>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <limits>

namespace {

using namespace rsibr;

EnvMap sky() {
  EnvMap env = EnvMap::zeros(Layout(LayoutKind::LatLong, 32, 16));
  env.pixels.setTo(cv::Scalar(0.5, 0.6, 0.8));
  return env;
}

MapSet icosa(int size) {
  MapSet set;
  const ViewSet views = ViewSet::named("icosa");
  for (const Vec3& v : views.views()) {
    MapView mv;
    mv.view = v;
    mv.world_from_view = world_from_view_for(v);
    mv.rgb = cv::Mat(size, size, CV_32FC3, cv::Scalar(0.2f, 0.3f, 0.4f));
    set.views.push_back(mv);
  }
  return set;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: rsibr_bad_inputs FOLDER\n";
    return 2;
  }
  const std::filesystem::path out = argv[1];
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  const std::pair<const char*, float> bad[] = {{"nan", nan}, {"inf", inf}, {"minus-inf", -inf}, {"flt-max", FLT_MAX}};
  for (const auto& [name, value] : bad) {
    EnvMap env = sky();
    env.pixels.at<cv::Vec3f>(3, 5)[1] = value;
    write_environment((out / (std::string("env-") + name + ".exr")).string(), env);
    MapSet maps = icosa(8);
    maps.views[4].rgb.at<cv::Vec3f>(2, 3)[0] = value;
    write_map_set((out / (std::string("maps-") + name + ".exr")).string(), maps);
  }
  EnvMap negative = sky();
  negative.pixels.at<cv::Vec3f>(1, 1) = cv::Vec3f(-0.5f, -1e-3f, 0.2f);
  write_environment((out / "env-negative.exr").string(), negative);
  MapSet conf = icosa(8);
  for (MapView& v : conf.views) {
    v.source = MapSource::Captured;
    v.confidence = cv::Mat(8, 8, CV_32FC1, cv::Scalar(1.f));
  }
  conf.views[2].confidence.at<float>(1, 1) = 2.f;
  conf.views[3].confidence.at<float>(4, 4) = nan;
  write_map_set((out / "maps-confidence.exr").string(), conf);
  write_map_set((out / "maps-1x1.exr").string(), icosa(1));
  MapSet one = icosa(8);
  one.views.resize(1);
  write_map_set((out / "maps-one-view.exr").string(), one);
  MapSet twice = icosa(8);
  twice.views[1] = twice.views[0];
  write_map_set((out / "maps-duplicate-view.exr").string(), twice);
  write_environment((out / "env-tiny.exr").string(), EnvMap::zeros(Layout(LayoutKind::LatLong, 4, 2)));
  write_map_set((out / "maps-good.exr").string(), icosa(8));
  write_environment((out / "env-good.exr").string(), sky());
  return 0;
}
