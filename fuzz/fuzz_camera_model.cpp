// libFuzzer target: the .cameramodel reader (mrcal's text format, through mrcal's C API), then a
// projection round trip through whatever model it read.
#include "core/lens_model.h"
#include "fuzz/fuzz_input.h"

#include <exception>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = rsibr::fuzz::input_file(data, size, ".cameramodel");
  try {
    const rsibr::LensModel lens = rsibr::LensModel::read(path);
    (void)lens.unproject(rsibr::Vec2(0.5 * lens.width(), 0.5 * lens.height()));
  } catch (const std::exception&) {
  }
  return 0;
}
