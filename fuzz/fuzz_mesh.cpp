// libFuzzer target: the mesh loaders (Wavefront OBJ through tinyobjloader, glTF binary through
// tinygltf and Draco). The first byte picks the extension.
#include "core/mesh.h"
#include "fuzz/fuzz_input.h"

#include <exception>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  const std::string path = rsibr::fuzz::input_file(data + 1, size - 1, (data[0] & 1) ? ".glb" : ".obj");
  try {
    (void)rsibr::load_mesh(path);
  } catch (const std::exception&) {
  }
  return 0;
}
