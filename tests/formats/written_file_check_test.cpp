#include "formats/written_file_check.h"

#include "formats/exr_file.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <stdexcept>
#include <string>

namespace fs = std::filesystem;
namespace rsibr {
namespace {

class WrittenFileCheck : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("rsibr_written_" + std::to_string(std::random_device{}()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path write(const std::string& name, const std::string& bytes) {
    std::ofstream(dir_ / name, std::ios::binary) << bytes;
    return dir_ / name;
  }
  std::string error_of(const fs::path& file, bool empty_allowed = false) {
    try {
      check_written_file(file, file, empty_allowed);
    } catch (const std::runtime_error& e) {
      return e.what();
    }
    return "";
  }
  fs::path exr(const std::string& name) {
    const fs::path p = dir_ / name;
    ExrPartOut part;
    const cv::Mat rgb(16, 32, CV_32FC3, cv::Scalar(1, 2, 3));
    for (int k = 0; k < 3; ++k) part.channels.push_back({std::string(1, "RGB"[k]), rgb, k});
    write_exr(p.string(), {part});
    return p;
  }
  fs::path dir_;
};

TEST_F(WrittenFileCheck, AnEmptyFileIsRefusedNamingTheFile) {
  const fs::path f = write("o.exr", "");
  const std::string e = error_of(f);
  EXPECT_NE(e.find(f.string() + ": cannot write"), std::string::npos) << e;
  EXPECT_NE(e.find("disk full"), std::string::npos) << e;
  EXPECT_EQ(error_of(write("empty.txt", ""), true), "");
}

TEST_F(WrittenFileCheck, AWholeExrPassesAndATruncatedOneDoesNot) {
  const fs::path good = exr("good.exr");
  EXPECT_EQ(error_of(good), "");
  std::ifstream in(good, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), {});
  for (std::size_t keep : {std::size_t(100), bytes.size() / 2, bytes.size() - 4})
    EXPECT_NE(error_of(write("cut" + std::to_string(keep) + ".exr", bytes.substr(0, keep))), "") << keep;
}

TEST_F(WrittenFileCheck, PngJpegAndJsonMustBeComplete) {
  const std::string iend("\0\0\0\0IEND\xAE\x42\x60\x82", 12);
  EXPECT_EQ(error_of(write("a.png", "\x89PNG....." + iend)), "");
  EXPECT_NE(error_of(write("b.png", "\x89PNG.....")), "");
  EXPECT_EQ(error_of(write("a.jpg", "\xFF\xD8....\xFF\xD9")), "");
  EXPECT_NE(error_of(write("b.jpg", "\xFF\xD8....")), "");
  EXPECT_EQ(error_of(write("a.json", "{\"a\": [1, 2]}\n")), "");
  EXPECT_NE(error_of(write("b.json", "{\"a\": [1, ")), "");
}

TEST_F(WrittenFileCheck, AFileChangedAfterItsCheckIsCheckedAgain) {
  const fs::path f = exr("noted.exr");
  check_written_file(f, f);
  note_checked_file(f);
  std::ifstream in(f, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), {});
  in.close();
  write("noted.exr", bytes.substr(0, bytes.size() / 2));  // a new size: the note no longer holds
  EXPECT_NE(error_of(f), "");
}

}  // namespace
}  // namespace rsibr
