#include "pipeline/compare_step.h"

#include "compare/comparison_report.h"
#include "compare/compare_pictures.h"
#include "compare/map_compare.h"
#include "formats/atomic_folder.h"
#include "formats/image_codecs.h"
#include "formats/map_set.h"

namespace rsibr {

namespace fs = std::filesystem;

StepOutputs run_compare_step(const CompareStep& s) {
  StepOutputs out;
  nlohmann::json balls = nlohmann::json::array();
  for (const CompareBall& b : s.balls) {
    MapSet captured = read_map_set(b.captured.string());
    MapSet computed = read_map_set(b.computed.string());
    // Views whose ball has no trusted texel cannot be compared: left out and listed (the bake made
    // one computed view per captured one, in order).
    std::vector<std::string> untrusted;
    if (captured.views.size() == computed.views.size()) {
      MapSet a, bset;
      for (std::size_t i = 0; i < captured.views.size(); ++i) {
        if (cv::countNonZero(captured.views[i].confidence > 0) == 0) {
          untrusted.push_back(!captured.views[i].image.empty() ? captured.views[i].image : "view." + std::to_string(i));
          continue;
        }
        a.views.push_back(std::move(captured.views[i]));
        bset.views.push_back(std::move(computed.views[i]));
      }
      if (a.views.empty()) {
        balls.push_back({{"ball", b.name}, {"views", nlohmann::json::array()}, {"untrusted_views", untrusted}});
        continue;
      }
      captured = std::move(a), computed = std::move(bset);
    }
    CompareOptions co;
    co.name_a = b.captured.string();
    co.name_b = b.computed.string();
    const Comparison cmp = compare_map_sets(captured, computed, co);
    // The same JSON and pictures as rsibr compare, plus the ball, each view's image and the views
    // left out.
    const ComparisonImages images = comparison_images(cmp);
    nlohmann::json bj = comparison_json(cmp, images, true);
    FolderContents files;
    for (std::size_t i = 0; i < cmp.pairs.size(); ++i) {
      const PairComparison& p = cmp.pairs[i];
      const std::string image = !captured.views[p.index_a].image.empty() ? captured.views[p.index_a].image : p.name;
      const std::string name = p.name + ".png";
      files[name] =
          png_bytes(comparison_panel(cmp, images, i, b.name + " " + image, "captured x gains", "computed"), name);
      bj["views"][i]["image"] = image;
      bj["views"][i]["picture"] = name;
    }
    const fs::path folder = s.out / b.name;
    fs::create_directories(s.out);
    write_folder_atomically(folder, files);
    for (const auto& [name, bytes] : files) out.files.push_back(folder / name);
    bj["ball"] = b.name;
    bj["folder"] = s.out.filename().string() + "/" + b.name;
    bj["untrusted_views"] = untrusted;
    bj["heat_max_stops"] = images.heat_max;
    bj["log_epsilon"] = cmp.settings.log_epsilon;
    balls.push_back(bj);
  }
  out.summary = {{"balls", balls}};
  return out;
}

}  // namespace rsibr
