// Given poses (pipeline/pose_input.h): both formats read, bad matrices and duplicates refused.
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
  const GivenPoses g = read_given_poses(p.string());
  ASSERT_EQ(g.views.size(), 1u);
  const Mat3& m = g.views.at("north").world_from_cam;
  EXPECT_EQ(m(0, 2), 1);   // row 0, column 2
  EXPECT_EQ(m(2, 0), -1);
  EXPECT_DOUBLE_EQ(g.views.at("north").sigma_deg, 0.03);
  EXPECT_EQ(g.gauge, "up");
  fs::remove(p);
}

TEST(GivenPoses, SynthTruthRowsAreRead) {
  const fs::path p = write_temp("t.yaml",
                                "rsibr_synth_truth: 1\nviews:\n  - name: view00\n    world_from_cam:\n"
                                "      - [1, 0, 0]\n      - [0, -1, 0]\n      - [0, 0, -1]\n");
  const GivenPoses g = read_given_poses(p.string());
  EXPECT_EQ(g.gauge, "truth");
  EXPECT_EQ(g.views.at("view00").world_from_cam(1, 1), -1);
  EXPECT_EQ(g.views.at("view00").sigma_deg, 0);
  fs::remove(p);
}

TEST(GivenPoses, NonRotationsDuplicatesAndUnknownFormatsAreErrorsNamingTheFile) {
  const std::string head = "rsibr_poses: 1\ngauge: up\nviews:\n";
  for (const std::string& bad :
       {head + "  - {name: a, world_from_cam: [2, 0, 0, 0, 1, 0, 0, 0, 1]}\n",
        head + "  - {name: a, world_from_cam: [-1, 0, 0, 0, 1, 0, 0, 0, 1]}\n",  // a reflection
        head + "  - {name: a, world_from_cam: [1, 0, 0, 0, 1, 0, 0, 0]}\n",
        head + "  - {name: a, world_from_cam: [1, 0, 0, 0, 1, 0, 0, 0, 1]}\n  - {name: a, world_from_cam: [1, 0, 0, 0, 1, 0, 0, 0, 1]}\n",
        std::string("views: []\n"), std::string("rsibr_poses: 1\ngauge: sideways\nviews: []\n")}) {
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
