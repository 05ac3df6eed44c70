// Given poses (pipeline/pose_input.h): poses.yaml (through calib/orientation/pose_file.h) and synth truth.yaml
// read, bad matrices and duplicates refused with the file's name.
#include "pipeline/pose_input.h"

#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>

namespace rsibr {
namespace {

namespace fs = std::filesystem;

fs::path write_temp(const std::string& name, const std::string& text) {
  const fs::path p = fs::temp_directory_path() / ("rsibr-poses-" + std::to_string(::getpid()) + "-" + name);
  std::ofstream(p) << text;
  return p;
}

TEST(GivenPoses, PosesFileRowsAreRowMajor) {
  const fs::path p = write_temp("a.yaml",
                                "rsibr_poses: 1\ngauge: up\nviews:\n"
                                "  - {name: north, world_from_cam: [0, 0, 1, 0, 1, 0, -1, 0, 0], sigma_deg: 0.03}\n");
  const PoseSet g = read_given_poses(p.string());
  ASSERT_EQ(g.views.size(), 1u);
  const Mat3& m = g.find("north")->world_from_cam;
  EXPECT_NEAR(m(0, 2), 1, 1e-12);  // row 0, column 2
  EXPECT_NEAR(m(2, 0), -1, 1e-12);
  EXPECT_DOUBLE_EQ(g.find("north")->sigma_deg, 0.03);
  EXPECT_EQ(g.gauge, "up");
  fs::remove(p);
}

TEST(GivenPoses, SynthTruthRowsAreRead) {
  const fs::path p = write_temp("t.yaml",
                                "rsibr_synth_truth: 1\nviews:\n  - name: view00\n    world_from_cam:\n"
                                "      - [1, 0, 0]\n      - [0, -1, 0]\n      - [0, 0, -1]\n");
  const PoseSet g = read_given_poses(p.string());
  EXPECT_EQ(g.gauge, "up");  // the synthetic world is +Y up
  EXPECT_EQ(g.find("view00")->world_from_cam(1, 1), -1);
  EXPECT_EQ(g.find("view00")->sigma_deg, 0);
  fs::remove(p);
}

TEST(GivenPoses, NonRotationsDuplicatesAndUnknownFormatsAreErrorsNamingTheFile) {
  const std::string head = "rsibr_poses: 1\ngauge: up\nviews:\n";
  for (
      const std::string& bad :
      {head + "  - {name: a, world_from_cam: [2, 0, 0, 0, 1, 0, 0, 0, 1]}\n",
       head + "  - {name: a, world_from_cam: [-1, 0, 0, 0, 1, 0, 0, 0, 1]}\n",  // a reflection
       head + "  - {name: a, world_from_cam: [1, 0, 0, 0, 1, 0, 0, 0]}\n",
       head +
           "  - {name: a, world_from_cam: [1, 0, 0, 0, 1, 0, 0, 0, 1]}\n  - {name: a, world_from_cam: [1, 0, 0, 0, 1, 0, 0, 0, 1]}\n",
       std::string("views: []\n"), std::string("rsibr_poses: 1\ngauge: sideways\nviews: []\n"),
       std::string(
           "rsibr_synth_truth: 1\nviews:\n  - {name: a, world_from_cam: [[1, 0, 0], [0, 1, 0], [0, 0, 2]]}\n")}) {
    const fs::path p = write_temp("bad.yaml", bad);
    try {
      read_given_poses(p.string());
      ADD_FAILURE() << "accepted:\n" << bad;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(p.string()), std::string::npos) << e.what();
    }
    fs::remove(p);
  }
  EXPECT_THROW(read_given_poses("/nonexistent/poses.yaml"), std::invalid_argument);
}

}  // namespace
}  // namespace rsibr
