#include "formats/truth_image.h"

#include "formats/exr_file.h"

namespace rsibr {

void write_truth_image(const std::filesystem::path& path, const cv::Mat& image, const CameraPose* pose,
                       const std::map<std::string, std::string>& attributes) {
  const int ch = image.channels();
  if (image.depth() != CV_32F || (ch != 1 && ch != 3))
    throw FileError(path.string(), "truth images are float RGB or Y", {}, FileRole::Output);
  ExrPartOut part;
  for (int k = 0; k < ch; ++k) part.channels.push_back({ch == 1 ? "Y" : std::string(1, "RGB"[k]), image, k});
  for (const auto& [k, v] : attributes) part.attributes.emplace_back("rsibr." + k, v);
  if (pose) {
    part.attributes.emplace_back("rsibr.worldFromCam", pose->world_from_cam);
    part.attributes.emplace_back("rsibr.eye", pose->eye);
  }
  write_exr(path.string(), {part});
}

cv::Mat read_truth_image(const std::filesystem::path& path) {
  const ExrFileIn file(path.string());
  const bool grey = file.parts().front().has_channel("Y");
  return file.read(0, grey ? std::vector<std::string>{"Y"} : std::vector<std::string>{"R", "G", "B"});
}

}  // namespace rsibr
