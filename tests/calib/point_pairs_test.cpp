// calib/orientation/point_pairs.h: a file of points picked by hand reads back as written; every malformed
// entry is one error naming the file and the key.
#include "calib/orientation/point_pairs.h"

#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>

namespace rsibr {
namespace {

namespace fs = std::filesystem;

fs::path write_points(const std::string& name, const std::string& text) {
  const fs::path p = fs::temp_directory_path() / ("rsibr-points-" + std::to_string(::getpid()) + "-" + name + ".yaml");
  std::ofstream(p) << text;
  return p;
}

std::string error_of(const fs::path& p) {
  try {
    read_point_pairs(p);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(PointPairs, AFileReadsBackAsWritten) {
  const fs::path p = write_points("good",
                                  "rsibr_points: 1\nsigma_px: 1.5\npoints:\n"
                                  "  - {name: lamp, a: [10.5, 20], b: [30, 40.25]}\n"
                                  "  - {a: [1, 2], b: [3, 4], c: [5, 6]}\n");
  const PointPairs pp = read_point_pairs(p);
  fs::remove(p);
  EXPECT_EQ(pp.sigma_px, 1.5);
  ASSERT_EQ(pp.points.size(), 2u);
  EXPECT_EQ(pp.points[0].name, "lamp");
  ASSERT_EQ(pp.points[0].seen.size(), 2u);
  EXPECT_EQ(pp.points[0].seen[0].first, "a");
  EXPECT_EQ(pp.points[0].seen[0].second, Vec2(10.5, 20));
  EXPECT_EQ(pp.points[0].seen[1].second, Vec2(30, 40.25));
  EXPECT_EQ(pp.points[1].seen.size(), 3u);
  EXPECT_NE(pp.points[1].where.find("points[1]"), std::string::npos);
}

TEST(PointPairs, MalformedEntriesAreOneErrorNamingTheFileAndTheKey) {
  const std::string head = "rsibr_points: 1\npoints:\n";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {head + "  - {a: [1, 2]}\n", "points.points[0]: a point must be given in two or more views"},
      {head + "  - {a: [1, 2], b: [3]}\n", "points.points[0].b: expected [x, y]"},
      {head + "  - {a: [1, .nan], b: [3, 4]}\n", "points.points[0].a[1]"},
      {head + "  - [1, 2]\n", "points.points[0]: expected a mapping"},
      {"rsibr_points: 2\npoints: [{a: [1, 2], b: [3, 4]}]\n", "unsupported version"},
      {"rsibr_points: 1\npoints: []\n", "expected a non-empty sequence"},
      {"rsibr_points: 1\nsigma_px: -1\npoints: [{a: [1, 2], b: [3, 4]}]\n", "sigma_px"},
  };
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const fs::path p = write_points("bad" + std::to_string(i), cases[i].first);
    const std::string e = error_of(p);
    fs::remove(p);
    EXPECT_EQ(e.rfind(p.string() + ": ", 0), 0u) << e;
    EXPECT_NE(e.find(cases[i].second), std::string::npos) << e;
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
  }
}

}  // namespace
}  // namespace rsibr
