// libFuzzer target: the map-set reader (multi-part OpenEXR with rsibr's attributes). Any input
// must give a map set or a std::exception: never a crash, a hang or a sanitizer report.
#include "formats/map_set.h"
#include "fuzz/fuzz_input.h"

#include <exception>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = rsibr::fuzz::input_file(data, size, ".exr");
  try {
    if (rsibr::is_map_set_file(path)) {
      long zeroed = 0;
      const rsibr::MapSet set = rsibr::read_map_set(path, rsibr::BadTexels::zero, &zeroed);
      (void)set.view_set();
    }
    (void)rsibr::read_map_set(path);
  } catch (const std::exception&) {
  }
  return 0;
}
