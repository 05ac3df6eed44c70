#include "pipeline/pose_input.h"

#include "core/safe_name.h"
#include "formats/yaml_spec.h"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <filesystem>
#include <stdexcept>

namespace rsibr {

namespace {

Mat3 parse_rows(const YAML::Node& node, const std::string& where) {
  if (!node.IsSequence() || node.size() != 3) throw std::invalid_argument(where + ": expected 3 rows of 3 numbers");
  Mat3 m;
  for (int r = 0; r < 3; ++r) {
    if (!node[r].IsSequence() || node[r].size() != 3)
      throw std::invalid_argument(where + ": expected 3 rows of 3 numbers");
    for (int c = 0; c < 3; ++c) {
      m(r, c) = node[r][c].as<double>();
      if (!std::isfinite(m(r, c))) throw std::invalid_argument(where + ": non-finite entry");
    }
  }
  if ((m.transpose() * m - Mat3::Identity()).cwiseAbs().maxCoeff() > 1e-4 || m.determinant() < 0)
    throw std::invalid_argument(where + ": not a rotation");
  return m;
}

}  // namespace

PoseSet read_given_poses(const std::string& path) {
  if (!std::filesystem::is_regular_file(path)) throw std::invalid_argument(path + ": no such file");
  const YAML::Node root = load_yaml_file(path);
  if (!root.IsMap() || !root["rsibr_synth_truth"]) return read_pose_file(path);  // its own errors
  PoseSet out;
  out.gauge = "up";  // the synthetic world is +Y up
  try {
    const YAML::Node views = root["views"];
    if (!views || !views.IsSequence() || views.size() == 0) throw std::invalid_argument("views: expected a list");
    DistinctNames names;
    for (std::size_t i = 0; i < views.size(); ++i) {
      const std::string where = "views[" + std::to_string(i) + "]";
      if (!views[i]["name"] || !views[i]["world_from_cam"])
        throw std::invalid_argument(where + ": needs name and world_from_cam");
      ViewPose p;
      p.name = views[i]["name"].as<std::string>();
      p.world_from_cam = parse_rows(views[i]["world_from_cam"], where + ".world_from_cam");
      names.add(p.name, where + ".name", "view");
      out.views.push_back(p);
    }
  } catch (const YAML::Exception& e) {
    throw std::invalid_argument(path + ": " + e.what());
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(path + ": " + e.what());
  }
  return out;
}

}  // namespace rsibr
