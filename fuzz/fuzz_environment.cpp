// libFuzzer target: the environment reader (OpenEXR lat-long / cube / octahedral / sphere, and
// Radiance .hdr through OpenCV), then a resample of what it read and its negative values folded
// (core/texel_audit.h). The first byte picks the extension the reader sees.
#include "formats/exr_io.h"
#include "core/resample.h"
#include "core/texel_audit.h"
#include "fuzz/fuzz_input.h"

#include <exception>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  const std::string path = rsibr::fuzz::input_file(data + 1, size - 1, (data[0] & 1) ? ".hdr" : ".exr");
  try {
    rsibr::EnvReadReport report;
    rsibr::EnvMap env = rsibr::read_environment(path, std::nullopt, &report);
    if (!report.texels.bad() && env.layout.texel_count() <= 4096) {
      rsibr::ResampleOptions o;
      o.max_subsamples = 2;
      (void)rsibr::resample(env, rsibr::Layout::with_size(rsibr::LayoutKind::Octahedral, 8), o);
      (void)rsibr::remove_negative_ringing(env.pixels);
    }
  } catch (const std::exception&) {
  }
  return 0;
}
