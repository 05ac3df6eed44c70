// libFuzzer target: the YAML specs a user hands rsibr: any YAML (anchors, aliases, nesting),
// BRDF specs, photo sets, pose files and synthetic scene specs. Every input must parse or be a std::exception.
#include "bake/brdf_spec.h"
#include "calib/orientation/pose_file.h"
#include "capture/synth_scene.h"
#include "formats/photo_set.h"
#include "formats/yaml_spec.h"
#include "fuzz/fuzz_input.h"

#include <exception>
#include <filesystem>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    (void)rsibr::parse_yaml(text, "fuzz");
  } catch (const std::exception&) {
  }
  try {
    (void)rsibr::parse_brdf(text);
  } catch (const std::exception&) {
  }
  try {
    (void)rsibr::parse_synth_scene(text, "scene.yaml", std::filesystem::temp_directory_path());
  } catch (const std::exception&) {
  }
  const std::string yaml = rsibr::fuzz::input_file(data, size, ".yaml");
  try {
    (void)rsibr::read_pose_file(yaml);
  } catch (const std::exception&) {
  }
  // A photo set is read from its folder: photoset.yaml next to the input.
  const std::filesystem::path set = std::filesystem::path(yaml).parent_path() / "photoset.yaml";
  std::filesystem::copy_file(yaml, set, std::filesystem::copy_options::overwrite_existing);
  try {
    (void)rsibr::load_photo_set(set);
  } catch (const std::exception&) {
  }
  return 0;
}
