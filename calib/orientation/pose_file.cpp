#include "calib/orientation/pose_file.h"

#include "formats/atomic_file.h"
#include "core/safe_name.h"
#include "formats/yaml_spec.h"

#include <Eigen/Dense>

#include <cmath>
#include <fstream>
#include <iomanip>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace rsibr {

namespace {

// Throws spec_fail(key, ...) unless m is a rotation to 1e-6; returns it re-orthonormalised.
Mat3 checked_rotation(const Mat3& m, const std::string& key) {
  if (!m.allFinite()) spec_fail(key, "non-finite entry");
  if ((m.transpose() * m - Mat3::Identity()).norm() > 1e-6 || m.determinant() < 0)
    spec_fail(key, "not a rotation (expected an orthonormal matrix with determinant +1)");
  Eigen::JacobiSVD<Mat3> svd(m, Eigen::ComputeFullU | Eigen::ComputeFullV);
  return svd.matrixU() * svd.matrixV().transpose();
}

void check(const PoseSet& p) {
  if (p.gauge != "first-view" && p.gauge != "up" && p.gauge != "estimated-up")
    spec_fail("poses.gauge", "expected first-view, up or estimated-up, got '" + p.gauge + "'");
  if (p.views.empty()) spec_fail("poses.views", "expected a non-empty sequence");
  DistinctNames names;
  for (std::size_t i = 0; i < p.views.size(); ++i) {
    const std::string key = "poses.views[" + std::to_string(i) + "]";
    const ViewPose& v = p.views[i];
    names.add(v.name, key + ".name", "view");
    checked_rotation(v.world_from_cam, key + ".world_from_cam");
    if (!(v.sigma_deg >= 0) || !std::isfinite(v.sigma_deg))
      spec_fail(key + ".sigma_deg", "must be a finite number >= 0");
    if (v.ball) {
      if (!v.ball->axis.allFinite() || std::abs(v.ball->axis.norm() - 1) > 1e-6)
        spec_fail(key + ".ball.axis", "expected a unit vector");
      if (!(v.ball->half_angle > 0 && v.ball->half_angle < kPi / 2))
        spec_fail(key + ".ball.half_angle_deg", "must lie in (0, 90)");
    }
  }
}

}  // namespace

const ViewPose* PoseSet::find(const std::string& name) const {
  for (const ViewPose& v : views)
    if (v.name == name) return &v;
  return nullptr;
}

PoseSet read_pose_file(const std::string& path) {
  try {
    const YAML::Node root = load_yaml_file(path);
    YamlMap top(root, "poses", {"rsibr_poses", "gauge", "views"});
    if (top.integer("rsibr_poses") != 1) spec_fail(top.at("rsibr_poses"), "unsupported version (expected 1)");
    PoseSet p;
    p.gauge = top.choice("gauge", {"first-view", "up", "estimated-up"});
    const YAML::Node views = top.get("views");
    if (!views.IsSequence() || views.size() == 0) spec_fail(top.at("views"), "expected a non-empty sequence");
    for (std::size_t i = 0; i < views.size(); ++i) {
      YamlMap v(views[i], top.at("views") + "[" + std::to_string(i) + "]",
                {"name", "world_from_cam", "sigma_deg", "ball"});
      ViewPose pose;
      pose.name = v.string("name");
      const std::vector<double> m = v.numbers("world_from_cam");
      if (m.size() != 9)
        spec_fail(v.at("world_from_cam"), "expected 9 numbers (row-major), got " + std::to_string(m.size()));
      Mat3 r;
      for (int k = 0; k < 9; ++k) r(k / 3, k % 3) = m[k];
      pose.world_from_cam = checked_rotation(r, v.at("world_from_cam"));
      pose.sigma_deg = v.number_in("sigma_deg", 0, false, std::numeric_limits<double>::infinity(), true);
      if (v.has("ball")) {
        YamlMap b(v.get("ball"), v.at("ball"), {"axis", "half_angle_deg"});
        const Vec3 axis = b.vec3("axis");
        if (!axis.allFinite() || std::abs(axis.norm() - 1) > 1e-6) spec_fail(b.at("axis"), "expected a unit vector");
        BallCone cone;
        cone.axis = axis.normalized();
        cone.half_angle = b.number_in("half_angle_deg", 0, true, 90, true) * kPi / 180;
        pose.ball = cone;
      }
      p.views.push_back(pose);
    }
    check(p);
    return p;
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    if (what.rfind(path, 0) == 0) throw;  // load_yaml_file already names the file
    throw std::invalid_argument(path + ": " + what);
  }
}

void write_pose_file(const std::string& path, const PoseSet& poses) {
  try {
    check(poses);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(path + ": " + e.what());
  }
  std::ostringstream out;
  out << std::setprecision(17);
  out << "rsibr_poses: 1\ngauge: " << poses.gauge << "\nviews:\n";
  for (const ViewPose& v : poses.views) {
    YAML::Emitter name;
    name << YAML::DoubleQuoted << v.name;  // any name survives the round trip
    out << "  - name: " << name.c_str() << "\n    world_from_cam: [";
    for (int k = 0; k < 9; ++k) out << (k ? ", " : "") << v.world_from_cam(k / 3, k % 3);
    // The std dev with 6 significant digits: an estimate, and its last bits vary between runs (the
    // sparse factorisations behind ceres::Covariance), which would break same input -> same bytes.
    out << "]\n    sigma_deg: " << std::setprecision(6) << v.sigma_deg << std::setprecision(17) << "\n";
    if (v.ball) {
      const Vec3& a = v.ball->axis;
      out << "    ball: {axis: [" << a.x() << ", " << a.y() << ", " << a.z()
          << "], half_angle_deg: " << v.ball->half_angle * 180 / kPi << "}\n";
    }
  }
  write_text_atomically(path, out.str());
}

}  // namespace rsibr
