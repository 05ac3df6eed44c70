// libFuzzer target: DIR/balls.json (calib/balls/balls_file.h), the balls step's findings, which a
// user may edit or copy between runs. Every input must parse or be a std::exception; a file that
// parses must be safe to use: its summary written, checked against a photo set's balls, written
// back and read again to the same balls.
#include "calib/balls/balls_file.h"
#include "fuzz/fuzz_input.h"

#include <cstdlib>
#include <exception>
#include <filesystem>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string file = rsibr::fuzz::input_file(data, size, ".json");
  rsibr::ShootBalls balls;
  try {
    balls = rsibr::read_balls_file(file);
  } catch (const std::exception&) {
    return 0;
  }
  (void)rsibr::balls_summary_json(balls).dump();
  try {
    rsibr::check_listed_balls(balls, {{"chrome", rsibr::BallKind::chrome, 0.1}}, "fuzz");
  } catch (const std::exception&) {
  }
  const std::filesystem::path again = std::filesystem::path(file).parent_path() / "again.json";
  rsibr::write_balls_file(again, balls);
  const rsibr::ShootBalls back = rsibr::read_balls_file(again);
  if (back.views.size() != balls.views.size() || back.listed.size() != balls.listed.size()) std::abort();
  for (std::size_t v = 0; v < balls.views.size(); ++v)
    if (back.views[v].candidates.size() != balls.views[v].candidates.size()) std::abort();
  return 0;
}
