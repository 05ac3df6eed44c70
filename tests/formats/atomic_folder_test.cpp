#include "formats/atomic_folder.h"

#include "core/test_data.h"

#include <gtest/gtest.h>

#include <fstream>

namespace rsibr {
namespace {

namespace fs = std::filesystem;

std::vector<unsigned char> bytes(const std::string& s) { return {s.begin(), s.end()}; }

std::string read(const fs::path& p) {
  std::ifstream in(p);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

TEST(AtomicFolder, CreatesTheFolderWithEveryFileAndNoStaging) {
  testing::TempDir dir;
  write_folder_atomically(dir.path() / "out", {{"a.txt", bytes("one")}, {"b.txt", bytes("two")}});
  EXPECT_EQ(read(dir.path() / "out" / "a.txt"), "one");
  EXPECT_EQ(read(dir.path() / "out" / "b.txt"), "two");
  int entries = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir.path())) ++entries;
  EXPECT_EQ(entries, 1);
}

TEST(AtomicFolder, AnExistingFolderKeepsOtherFiles) {
  testing::TempDir dir;
  fs::create_directory(dir.path() / "out");
  std::ofstream(dir.path() / "out" / "keep.txt") << "kept";
  std::ofstream(dir.path() / "out" / "a.txt") << "old";
  write_folder_atomically(dir.path() / "out/", {{"a.txt", bytes("new")}});
  EXPECT_EQ(read(dir.path() / "out" / "keep.txt"), "kept");
  EXPECT_EQ(read(dir.path() / "out" / "a.txt"), "new");
}

TEST(AtomicFolder, ErrorsLeaveNothingBehind) {
  testing::TempDir dir;
  EXPECT_THROW(write_folder_atomically(dir.path() / "missing" / "out", {{"a.txt", bytes("x")}}), std::invalid_argument);
  EXPECT_THROW(write_folder_atomically(dir.path() / "out", {{"a.txt", bytes("x")}, {"sub/b.txt", bytes("y")}}),
               std::invalid_argument);
  std::ofstream(dir.path() / "file") << "x";
  EXPECT_THROW(write_folder_atomically(dir.path() / "file", {{"a.txt", bytes("x")}}), std::invalid_argument);
  int entries = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir.path())) ++entries;
  EXPECT_EQ(entries, 1);  // only "file"
}

}  // namespace
}  // namespace rsibr
