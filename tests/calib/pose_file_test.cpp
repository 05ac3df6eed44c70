// calib/orientation/pose_file.h: poses.yaml round trip (bit-exact) and strict reading (one error naming the file
// and the key).
#include "calib/orientation/pose_file.h"

#include "formats/file_error.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <filesystem>
#include <fstream>

namespace rsibr {
namespace {

namespace fs = std::filesystem;

fs::path temp_dir() {
  const fs::path d = fs::temp_directory_path() / ("rsibr-pose-test-" + std::to_string(::getpid()));
  fs::create_directories(d);
  return d;
}

std::string error_of(const std::string& path) {
  try {
    read_pose_file(path);
  } catch (const std::invalid_argument& e) {
    return e.what();
  } catch (const FileError& e) {  // a missing or unreadable file
    return e.what();
  }
  return "";
}

void write_text(const fs::path& p, const std::string& text) { std::ofstream(p) << text; }

TEST(PoseFile, RoundTripKeepsRotationsExactAndSigmasToSixDigits) {
  PoseSet p;
  p.gauge = "up";
  p.views.push_back(
      {"north", Eigen::AngleAxisd(0.3, Vec3(1, 2, 3).normalized()).toRotationMatrix(), 0.0312345678901, std::nullopt});
  p.views.push_back({"Side-2.5_b", Eigen::AngleAxisd(-2.9, Vec3(0, 1, 0)).toRotationMatrix(), 0, std::nullopt});
  BallCone ball;
  ball.axis = Vec3(0.1, -0.2, 1).normalized();
  ball.half_angle = 0.0998;
  p.views[1].ball = ball;
  const fs::path f = temp_dir() / "poses.yaml";
  write_pose_file(f.string(), p);
  const PoseSet q = read_pose_file(f.string());
  ASSERT_EQ(q.views.size(), 2u);
  EXPECT_EQ(q.gauge, "up");
  for (int v = 0; v < 2; ++v) {
    EXPECT_EQ(q.views[v].name, p.views[v].name);
    EXPECT_NEAR(q.views[v].sigma_deg, p.views[v].sigma_deg, 1e-5 * p.views[v].sigma_deg);
    // Re-orthonormalising an orthonormal matrix written with 17 digits moves it by rounding only.
    EXPECT_LT((q.views[v].world_from_cam - p.views[v].world_from_cam).cwiseAbs().maxCoeff(), 1e-15);
  }
  // The refined ball: absent stays absent; present comes back to rounding.
  EXPECT_FALSE(q.views[0].ball.has_value());
  ASSERT_TRUE(q.views[1].ball.has_value());
  EXPECT_LT((q.views[1].ball->axis - ball.axis).norm(), 1e-15);
  EXPECT_NEAR(q.views[1].ball->half_angle, ball.half_angle, 1e-15);
  ASSERT_NE(q.find("north"), nullptr);
  EXPECT_EQ(q.find("south"), nullptr);
  fs::remove_all(f.parent_path());
}

TEST(PoseFile, StrictReadingNamesTheFileAndTheKey) {
  const fs::path d = temp_dir();
  const std::string ok_view = "{name: a, world_from_cam: [1, 0, 0, 0, 1, 0, 0, 0, 1], sigma_deg: 0}";
  struct Case {
    std::string text, expect;
  } cases[] = {
      {"rsibr_poses: 1\ngauge: first-view\nviews: [" + ok_view + "]\nextra: 1\n", "poses.extra: unknown key"},
      {"rsibr_poses: 2\ngauge: first-view\nviews: [" + ok_view + "]\n", "unsupported version"},
      {"rsibr_poses: 1\ngauge: level\nviews: [" + ok_view + "]\n", "poses.gauge"},
      {"rsibr_poses: 1\ngauge: up\nviews: []\n", "poses.views: expected a non-empty sequence"},
      {"rsibr_poses: 1\ngauge: up\nviews: [{name: a, world_from_cam: [1, 0, 0, 0, 1, 0, 0, 0], sigma_deg: 0}]\n",
       "poses.views[0].world_from_cam: expected 9 numbers"},
      {"rsibr_poses: 1\ngauge: up\nviews: [{name: a, world_from_cam: [1, 0, 0, 0, 1, 0, 0, 0, 2], sigma_deg: 0}]\n",
       "poses.views[0].world_from_cam: not a rotation"},
      {"rsibr_poses: 1\ngauge: up\nviews: [{name: a, world_from_cam: [1, 0, 0, 0, 1, 0, 0, 0, -1], sigma_deg: 0}]\n",
       "not a rotation"},
      {"rsibr_poses: 1\ngauge: up\nviews: [{name: a, world_from_cam: [1, 0, 0, 0, 1, 0, 0, 0, 1], sigma_deg: -1}]\n",
       "poses.views[0].sigma_deg"},
      {"rsibr_poses: 1\ngauge: up\nviews: [{name: a, world_from_cam: [1, 0, 0, 0, 1, 0, 0, 0, 1]}]\n",
       "poses.views[0].sigma_deg: missing"},
      {"rsibr_poses: 1\ngauge: up\nviews: [" + ok_view + ", " + ok_view + "]\n", "duplicate view name 'a'"},
      {"rsibr_poses: 1\ngauge: up\nviews: [{name: \"../a\", world_from_cam: [1, 0, 0, 0, 1, 0, 0, 0, 1], sigma_deg: 0}]\n",
       "poses.views[0].name: a name starting with '.'"},
      {"rsibr_poses: 1\ngauge: up\nviews: [{name: \"with space\", world_from_cam: [1, 0, 0, 0, 1, 0, 0, 0, 1], sigma_deg: 0}]\n",
       "poses.views[0].name: a name containing ' '"},
      {"rsibr_poses: 1\ngauge: up\nviews: [{name: a, world_from_cam: [1, 0, 0, 0, 1, 0, 0, 0, .nan], sigma_deg: 0}]\n",
       "world_from_cam"},
      {"rsibr_poses: 1\ngauge: [up\n", "poses.yaml"},
      {"rsibr_poses: 1\ngauge: up\nviews: [{name: a, world_from_cam: [1, 0, 0, 0, 1, 0, 0, 0, 1], sigma_deg: 0, "
       "ball: {axis: [0, 0, 2], half_angle_deg: 5}}]\n",
       "poses.views[0].ball.axis: expected a unit vector"},
      {"rsibr_poses: 1\ngauge: up\nviews: [{name: a, world_from_cam: [1, 0, 0, 0, 1, 0, 0, 0, 1], sigma_deg: 0, "
       "ball: {axis: [0, 0, 1], half_angle_deg: 90}}]\n",
       "poses.views[0].ball.half_angle_deg"},
      {"rsibr_poses: 1\ngauge: up\nviews: [{name: a, world_from_cam: [1, 0, 0, 0, 1, 0, 0, 0, 1], sigma_deg: 0, "
       "ball: {axis: [0, 0, 1]}}]\n",
       "poses.views[0].ball.half_angle_deg: missing"},
  };
  for (const Case& c : cases) {
    const fs::path f = d / "poses.yaml";
    write_text(f, c.text);
    const std::string e = error_of(f.string());
    EXPECT_EQ(e.rfind(f.string(), 0), 0u) << c.text << " -> " << e;
    EXPECT_NE(e.find(c.expect), std::string::npos) << c.text << " -> " << e;
  }
  EXPECT_NE(error_of((d / "missing.yaml").string()).find("missing.yaml"), std::string::npos);
  fs::remove_all(d);
}

TEST(PoseFile, AnInvalidSetIsNotWrittenAndLeavesNoFile) {
  const fs::path d = temp_dir();
  PoseSet p;
  p.views.push_back({"a", Mat3::Identity() * 2, 0, std::nullopt});
  EXPECT_THROW(write_pose_file((d / "p.yaml").string(), p), std::invalid_argument);
  p.views[0].world_from_cam = Mat3::Identity();
  p.views[0].sigma_deg = std::numeric_limits<double>::infinity();
  EXPECT_THROW(write_pose_file((d / "p.yaml").string(), p), std::invalid_argument);
  EXPECT_TRUE(fs::is_empty(d));
  fs::remove_all(d);
}

}  // namespace
}  // namespace rsibr
