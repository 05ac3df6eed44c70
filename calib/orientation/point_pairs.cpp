#include "calib/orientation/point_pairs.h"

#include "formats/yaml_spec.h"

#include <cmath>
#include <stdexcept>

namespace rsibr {

PointPairs read_point_pairs(const std::filesystem::path& file) {
  const std::string path = file.string();
  try {
    const YAML::Node root = load_yaml_file(file);
    YamlMap top(root, "points", {"rsibr_points", "sigma_px", "points"});
    if (top.integer("rsibr_points") != 1) spec_fail(top.at("rsibr_points"), "unsupported version (expected 1)");
    PointPairs out;
    if (top.has("sigma_px")) out.sigma_px = top.positive("sigma_px");
    const YAML::Node points = top.get("points");
    if (!points.IsSequence() || points.size() == 0) spec_fail(top.at("points"), "expected a non-empty sequence");
    for (std::size_t i = 0; i < points.size(); ++i) {
      const std::string at = top.at("points") + "[" + std::to_string(i) + "]";
      if (!points[i].IsMap()) spec_fail(at, "expected a mapping of view names to [x, y] pixels");
      PickedPoint p;
      p.where = path + ": " + at;
      for (const auto& kv : points[i]) {
        const std::string key = kv.first.as<std::string>();
        if (key == "name") {
          p.name = kv.second.as<std::string>();
          continue;
        }
        const YAML::Node& xy = kv.second;
        if (!xy.IsSequence() || xy.size() != 2) spec_fail(at + "." + key, "expected [x, y], the pixel in that view");
        const Vec2 q(spec_number(xy[0], at + "." + key + "[0]"), spec_number(xy[1], at + "." + key + "[1]"));
        if (!q.allFinite()) spec_fail(at + "." + key, "the pixel must be finite");
        for (const auto& [view, px] : p.seen)
          if (view == key) spec_fail(at + "." + key, "the view is given twice");
        p.seen.push_back({key, q});
      }
      if (p.seen.size() < 2)
        spec_fail(at, "a point must be given in two or more views (it ties them together), got " +
                          std::to_string(p.seen.size()));
      out.points.push_back(std::move(p));
    }
    return out;
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    if (what.rfind(path, 0) == 0) throw;
    throw std::invalid_argument(path + ": " + what);
  } catch (const YAML::Exception& e) {
    throw std::invalid_argument(path + ": " + e.what());
  }
}

}  // namespace rsibr
