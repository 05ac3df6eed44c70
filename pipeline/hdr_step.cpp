#include "pipeline/hdr_step.h"

#include "core/colour.h"
#include "core/progress.h"
#include "formats/atomic_file.h"
#include "formats/atomic_folder.h"
#include "hdr/bracket_set.h"
#include "hdr/merged_colour.h"
#include "hdr/merged_exr.h"
#include "hdr/photo_set_merge.h"
#include "hdr/response_recovery.h"
#include "pipeline/vignetting_input.h"
#include "calib/view_image.h"

#include <cmath>
#include <stdexcept>

namespace rsibr {

namespace fs = std::filesystem;

StepOutputs run_hdr_step(const HdrStep& s) {
  if (!s.set) throw std::invalid_argument("hdr: no photo set");
  StepOutputs result;
  // The camera's colour space (hdr/merged_colour.h): the option, else the photo set's; RAW views
  // are developed to linear Rec.709 (hdr/raw_image.h) whatever the photo set says.
  const std::string input_space = !s.input_colour_space.empty() ? s.input_colour_space : s.set->camera_colour_space;
  fs::create_directories(s.out);
  std::vector<const PhotoView*> all;
  for (const PhotoView& v : s.set->views) all.push_back(&v);
  const PhotoSetResponse psr = recover_photo_set_response(all, RecoveryOptions{}, Alignment::automatic);
  const ResponseRecovery& rec = psr.recovery;
  const std::string from = psr.from.empty() ? std::string("none: one exposure per view, the sRGB response stated")
                                            : std::to_string(psr.from.size()) + " views (all with brackets)";
  const ResponseCurve& curve = rec.curve;
  nlohmann::json cands = nlohmann::json::array();
  for (const auto& k : rec.candidates)
    cands.push_back({{"model", k.model},
                     {"held_out_error", std::isfinite(k.held_out_error) ? nlohmann::json(k.held_out_error)
                                                                        : nlohmann::json("rejected")}});
  const fs::path response = s.out / "response.json";
  save_response(response, curve,
                {{"camera", s.set->camera_name}, {"recovered_from", from}, {"recovery", recovery_json(rec)}});
  nlohmann::json plot = nlohmann::json::array();
  for (int k = 0; k <= 64; ++k) {
    const double z = double(k) * curve.max_code / 64;
    plot.push_back({z, curve.linear(0, z), curve.linear(1, z), curve.linear(2, z)});
  }
  result.files.push_back(response);
  nlohmann::json vignetting;
  const Vignetting vig = photo_set_vignetting(*s.set, s.vignetting, curve, LensModel::read(s.lens), &vignetting);
  const fs::path vfile = s.out / "vignetting.json";
  write_text_atomically(vfile, vignetting["model"].dump(2) + "\n");
  result.files.push_back(vfile);
  nlohmann::json views = nlohmann::json::array();
  Progress bar("hdr", s.progress);
  for (std::size_t i = 0; i < s.set->views.size(); ++i) {
    const PhotoView& v = s.set->views[i];
    ViewMergeSettings vs;
    vs.noise = psr.noise;
    vs.vignetting = &vig;
    vs.input_colour_space = s.input_colour_space;
    vs.camera_colour_space = s.set->camera_colour_space;
    ViewMerge vm = merge_view_radiance(v, curve, vs);
    const BracketSet& b = vm.brackets;
    const NoiseModel& noise = vm.noise;
    MergedImage& m = vm.image;
    const std::string& from = vm.input_colour_space;
    const fs::path exr = file_in_folder(s.out, v.name + ".exr");
    write_merged_exr(exr.string(), m,
                     {{"version", RSIBR_VERSION},
                      {"view", v.name},
                      {"responseModel", curve.model},
                      {"responseFile", "response.json (next to this file)"},
                      {"colourSpace", working_space()},
                      {"inputColourSpace", from.empty() ? working_space() : from},
                      {"radianceUnit", "X/e: signal over saturation per relative exposure t*iso/100/N^2"},
                      {"producer", "rsibr process (hdr step)"}});
    result.files.push_back(exr);
    const double px = double(m.radiance.total());
    nlohmann::json shifts = nlohmann::json::array(), bracket_names = nlohmann::json::array();
    for (const cv::Point& sh : vm.shifts) shifts.push_back({sh.x, sh.y});
    for (const std::string& f : b.files) bracket_names.push_back(fs::path(f).filename().string());
    views.push_back({{"name", v.name},
                     {"brackets", b.size()},
                     {"clipped_fraction", m.clipped / px},
                     {"clipped_pixels", m.clipped},
                     {"ghost_fraction", m.ghost / px},
                     {"noise_read", noise.read},
                     {"noise_shot", noise.shot},
                     {"alignment_shifts", shifts},
                     {"alignment_rotations_deg", vm.alignment.rotation_deg},
                     {"alignment_beyond_search", vm.alignment.beyond_search},
                     {"alignment_mismatch_after", vm.alignment.mismatch_after},
                     {"bracket_files", bracket_names},
                     {"sizes_fitted", b.fitted_sizes}});
    bar.update(double(i + 1) / double(s.set->views.size()));
  }
  bar.done();
  result.summary = {{"model", curve.model},
                    {"recovered_from", from},
                    {"candidates", cands},
                    {"recovery", recovery_json(rec)},
                    {"curve", plot},
                    {"max_code", curve.max_code},
                    {"views", views},
                    {"vignetting", vignetting},
                    {"camera", s.set->camera_name},
                    {"input_colour_space", input_space.empty() ? working_space() : input_space},
                    {"colour_space", working_space()}};
  return result;
}

std::vector<fs::path> given_radiance_files(const PhotoSet& set, const std::string& folder) {
  std::vector<fs::path> files;
  for (const PhotoView& v : set.views) {
    const fs::path a = fs::path(folder) / (v.name + "_radiance.exr"), b = fs::path(folder) / (v.name + ".exr");
    if (fs::is_regular_file(a))
      files.push_back(a);
    else if (fs::is_regular_file(b))
      files.push_back(b);
    else
      throw std::invalid_argument(folder + ": no " + a.filename().string() + " or " + b.filename().string());
  }
  return files;
}

StepOutputs run_given_radiance_step(const PhotoSet& set, const std::vector<fs::path>& files, const std::string& folder,
                                    const fs::path& out) {
  if (files.size() != set.views.size()) throw std::invalid_argument("hdr: one given image per view expected");
  StepOutputs result;
  fs::create_directories(out);
  nlohmann::json views = nlohmann::json::array();
  for (std::size_t i = 0; i < set.views.size(); ++i) {
    const ViewImage img = read_view_image(files[i].string());
    MergedImage m;
    m.radiance = img.radiance;
    m.variance = cv::Mat::zeros(img.radiance.size(), CV_32FC3);
    m.flags = cv::Mat::zeros(img.radiance.size(), CV_8UC1);
    const fs::path exr = file_in_folder(out, set.views[i].name + ".exr");
    write_merged_exr(exr.string(), m,
                     {{"version", RSIBR_VERSION},
                      {"view", set.views[i].name},
                      {"source", files[i].string()},
                      {"producer", "rsibr process (given radiance)"}});
    result.files.push_back(exr);
    views.push_back({{"name", set.views[i].name}, {"brackets", 0}, {"clipped_fraction", 0.0}, {"ghost_fraction", 0.0}});
  }
  result.summary = {{"model", "given radiance (" + folder + ")"},
                    {"recovered_from", "-"},
                    {"curve", nlohmann::json::array()},
                    {"views", views}};
  return result;
}

std::string suspect_bracket(const std::string& view, const nlohmann::json& hdr) {
  if (!hdr.is_object() || !hdr.contains("views")) return "";
  for (const auto& vj : hdr["views"]) {
    if (vj.value("name", "") != view || !vj.contains("alignment_mismatch_after")) continue;
    // In the merge's order (by exposure), the middle one the reference.
    const auto& m = vj["alignment_mismatch_after"];
    const auto& shifts = vj["alignment_shifts"];
    const auto& files = vj.value("bracket_files", nlohmann::json::array());
    const std::size_t n = std::min(m.size(), files.size());
    std::size_t worst = n;
    for (std::size_t j = 0; j < n; ++j)
      if (j != n / 2 && (worst == n || m[j].get<double>() > m[worst].get<double>())) worst = j;
    if (worst == n) return "";
    std::string text = files[worst].get<std::string>();
    if (worst < shifts.size())
      text += " (moved " + std::to_string(shifts[worst][0].get<int>()) + "," +
              std::to_string(shifts[worst][1].get<int>()) + " px; " +
              std::to_string(int(std::lround(100 * m[worst].get<double>()))) + "% of its bitmap disagrees)";
    return text;
  }
  return "";
}

}  // namespace rsibr
