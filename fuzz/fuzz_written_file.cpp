// libFuzzer target: the read-back of a file just written (formats/written_file_check.h: an EXR decoded,
// a PNG's or JPEG's end marker, a JSON parse) and the JPEG completeness walk of the photo reader
// (formats/image_codecs.h), on any bytes. The first byte picks the extension the check sees.
#include "formats/image_codecs.h"
#include "formats/written_file_check.h"
#include "fuzz/fuzz_input.h"

#include <exception>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  static const char* const extensions[] = {".exr", ".png", ".jpg", ".json"};
  const std::string path = rsibr::fuzz::input_file(data + 1, size - 1, extensions[data[0] % 4]);
  try {
    rsibr::check_written_file(path, path);
  } catch (const std::exception&) {
  }
  (void)rsibr::jpeg_is_complete(path);
  return 0;
}
