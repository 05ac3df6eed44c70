#include "pipeline/pose_input.h"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <filesystem>
#include <stdexcept>

namespace rsibr {

namespace {

Mat3 parse_matrix(const YAML::Node& node, const std::string& where) {
  std::vector<double> v;
  if (node.IsSequence() && node.size() == 3 && node[0].IsSequence()) {
    for (const auto& row : node) {
      if (!row.IsSequence() || row.size() != 3) throw std::invalid_argument(where + ": expected 3 rows of 3 numbers");
      for (const auto& x : row) v.push_back(x.as<double>());
    }
  } else if (node.IsSequence() && node.size() == 9) {
    for (const auto& x : node) v.push_back(x.as<double>());
  } else {
    throw std::invalid_argument(where + ": expected 9 numbers (row-major) or 3 rows of 3");
  }
  Mat3 m;
  for (int i = 0; i < 9; ++i) {
    if (!std::isfinite(v[i])) throw std::invalid_argument(where + ": non-finite entry");
    m(i / 3, i % 3) = v[i];
  }
  if ((m.transpose() * m - Mat3::Identity()).cwiseAbs().maxCoeff() > 1e-4 || m.determinant() < 0)
    throw std::invalid_argument(where + ": not a rotation");
  return m;
}

}  // namespace

GivenPoses read_given_poses(const std::string& path) {
  if (!std::filesystem::is_regular_file(path)) throw std::invalid_argument(path + ": no such file");
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const std::exception& e) {
    throw std::invalid_argument(path + ": " + e.what());
  }
  GivenPoses out;
  try {
    if (root["rsibr_poses"]) {
      if (root["rsibr_poses"].as<int>() != 1) throw std::invalid_argument("rsibr_poses: unsupported version");
      out.source = "poses.yaml";
      out.gauge = root["gauge"] ? root["gauge"].as<std::string>() : "";
      if (out.gauge != "first-view" && out.gauge != "up")
        throw std::invalid_argument("gauge: expected first-view or up");
    } else if (root["rsibr_synth_truth"]) {
      out.source = "synth truth";
      out.gauge = "truth";
    } else {
      throw std::invalid_argument("neither a poses file (rsibr_poses: 1) nor a synth truth.yaml");
    }
    const YAML::Node views = root["views"];
    if (!views || !views.IsSequence() || views.size() == 0) throw std::invalid_argument("views: expected a list");
    for (std::size_t i = 0; i < views.size(); ++i) {
      const std::string where = "views[" + std::to_string(i) + "]";
      if (!views[i]["name"] || !views[i]["world_from_cam"])
        throw std::invalid_argument(where + ": needs name and world_from_cam");
      const std::string name = views[i]["name"].as<std::string>();
      GivenPose p;
      p.world_from_cam = parse_matrix(views[i]["world_from_cam"], where + ".world_from_cam");
      if (views[i]["sigma_deg"]) p.sigma_deg = views[i]["sigma_deg"].as<double>();
      if (!(p.sigma_deg >= 0) || !std::isfinite(p.sigma_deg)) throw std::invalid_argument(where + ".sigma_deg: expected >= 0");
      if (!out.views.emplace(name, p).second) throw std::invalid_argument(where + ": duplicate view name '" + name + "'");
    }
  } catch (const YAML::Exception& e) {
    throw std::invalid_argument(path + ": " + e.what());
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(path + ": " + e.what());
  }
  return out;
}

}  // namespace rsibr
