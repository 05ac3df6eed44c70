#include "formats/atomic_folder.h"
#include "core/safe_name.h"
#include "core/text.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "error_message.h"

namespace fs = std::filesystem;
namespace rsibr {
namespace {

using test_support::error_of;

TEST(SafeName, NamesOfLettersDigitsDotsDashesAndUnderscoresAreSafe) {
  for (const std::string& name : {std::string("north"), std::string("view00"), std::string("Grey_ball-2"),
                                  std::string("v1.5"), std::string("0"), std::string(kMaxNameLength, 'x')})
    EXPECT_EQ(name_problem(name), "") << name;
}

TEST(SafeName, EveryNameThatCouldLeaveTheFolderOrHideIsRefused) {
  const std::string nul("a\0b", 3);
  for (const std::string& name : std::vector<std::string>{
           "", ".", "..", "../x", "../../esc/stolen", "/abs", "a/b", "a\\b", ".hidden", "-v", "_x", "a b", "a\tb", nul,
           "caf\xC3\xA9", "\xFF", "x:y", "<script>", std::string(kMaxNameLength + 1, 'x')})
    EXPECT_NE(name_problem(name), "") << quoted_for_message(name);
}

TEST(SafeName, TheErrorIsOneBoundedLineNamingWhereAndTheName) {
  const std::string hostile = "../" + std::string(10000, 'a') + "\n\x1b[31m";
  const std::string e = error_of([&] { require_safe_name(hostile, "set.yaml: views[3].name"); });
  EXPECT_EQ(e.rfind("set.yaml: views[3].name: ", 0), 0u) << e;
  EXPECT_EQ(e.find('\n'), std::string::npos);
  EXPECT_EQ(e.find('\x1b'), std::string::npos) << "control characters are written as \\xNN";
  EXPECT_LT(e.size(), 300u);
  EXPECT_NE(e.find("10009 bytes"), std::string::npos) << e;
}

TEST(SafeName, DistinctNamesRefuseDuplicatesAndNamesEqualUpToLetterCase) {
  DistinctNames names;
  names.add("North", "f: views[0].name", "view");
  names.add("south", "f: views[1].name", "view");
  EXPECT_NE(error_of([&] {
              names.add("north", "f: views[2].name", "view");
            }).find("f: views[2].name: view name 'north' clashes with 'North'"),
            std::string::npos);
  EXPECT_NE(error_of([&] { names.add("south", "f: views[3].name", "view"); }).find("duplicate view name 'south'"),
            std::string::npos);
  EXPECT_NE(error_of([&] { names.add("..", "f: views[4].name", "view"); }).find("folder reference"), std::string::npos);
}

TEST(Utf8, WellFormedTextIsKeptByteForByte) {
  for (const std::string s : {"", "plain", "caf\xC3\xA9", "\xE2\x82\xAC 5", "\xF0\x9F\x98\x80", "\xF4\x8F\xBF\xBF"}) {
    EXPECT_TRUE(is_utf8(s));
    EXPECT_EQ(valid_utf8(s), s);
  }
}

TEST(Utf8, IllFormedSequencesAreEachReplacedByOneReplacementCharacter) {
  const std::string fffd = "\xEF\xBF\xBD";
  // A lone Latin-1 byte, a truncated sequence, an overlong '/', a UTF-16 surrogate, a code point
  // above U+10FFFF, a stray continuation byte.
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"caf\xE9", "caf" + fffd},
      {"x\xE2\x82", "x" + fffd + fffd},
      {"\xC0\xAF", fffd + fffd},
      {"\xED\xA0\x80", fffd + fffd + fffd},
      {"\xF4\x90\x80\x80", fffd + fffd + fffd + fffd},
      {"\x80"
       "a",
       fffd + "a"},
  };
  for (const auto& [in, out] : cases) {
    EXPECT_FALSE(is_utf8(in)) << quoted_for_message(in);
    EXPECT_EQ(valid_utf8(in), out) << quoted_for_message(in);
  }
}

TEST(Utf8, ValidUtf8OfAnyBytesIsWellFormedAndKeepsItsAsciiBytes) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 2000; ++trial) {
    std::string s(std::size_t(rng() % 24), '\0');
    for (char& c : s) c = char(rng() & 0xFF);
    const std::string v = valid_utf8(s);
    EXPECT_TRUE(is_utf8(v)) << quoted_for_message(s);
    std::string ascii_in, ascii_out;
    for (char c : s)
      if (static_cast<unsigned char>(c) < 0x80) ascii_in += c;
    for (char c : v)
      if (static_cast<unsigned char>(c) < 0x80) ascii_out += c;
    EXPECT_EQ(ascii_in, ascii_out);
  }
}

TEST(Utf8, QuotedForMessageIsPrintableAndBounded) {
  EXPECT_EQ(quoted_for_message("a\tb\xFF"), "a\\x09b\\xFF");
  EXPECT_EQ(quoted_for_message("caf\xC3\xA9"), "caf\xC3\xA9");
  const std::string q = quoted_for_message(std::string(1000, 'z'), 10);
  EXPECT_EQ(q, std::string(10, 'z') + "...(1000 bytes)");
}

class FileInFolderTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("rsibr_file_in_folder_" + std::to_string(std::random_device{}()));
    fs::create_directories(dir_ / "out");
    fs::create_directories(dir_ / "elsewhere");
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

TEST_F(FileInFolderTest, AFileNameGivesAPathDirectlyInTheFolder) {
  EXPECT_EQ(file_in_folder(dir_ / "out", "north.exr"), dir_ / "out" / "north.exr");
  EXPECT_EQ(file_in_folder(dir_ / "new", "north.exr"), dir_ / "new" / "north.exr") << "the folder may not exist yet";
}

TEST_F(FileInFolderTest, NamesWithFoldersOrFolderReferencesAreRefused) {
  for (const std::string& name :
       std::vector<std::string>{"", ".", "..", "../x.exr", "a/b.exr", "/etc/x", std::string("a\0b", 3)})
    EXPECT_NE(error_of([&] { file_in_folder(dir_ / "out", name); }), "") << quoted_for_message(name);
}

TEST_F(FileInFolderTest, AnExistingLinkOfThatNameIsReplacedByTheWriteNotFollowed) {
  // The contract of every writer: a finished temporary renamed onto the path replaces the link.
  std::ofstream(dir_ / "elsewhere" / "victim") << "keep";
  fs::create_symlink(dir_ / "elsewhere" / "victim", dir_ / "out" / "north.txt");
  const fs::path p = file_in_folder(dir_ / "out", "north.txt");
  write_folder_atomically(dir_ / "out", {{"north.txt", {'n', 'e', 'w'}}});
  std::ifstream victim(dir_ / "elsewhere" / "victim");
  std::string text;
  victim >> text;
  EXPECT_EQ(text, "keep");
  EXPECT_FALSE(fs::is_symlink(p));
}

}  // namespace
}  // namespace rsibr
