// rsibr info: the header and value summary of an environment map or a map set.
#include "cli/summary.h"
#include "cli/verbs.h"

#include "formats/exr_io.h"
#include "formats/map_set.h"
#include "formats/output_plan.h"
#include "core/luminance.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>

namespace rsibr::cli {
namespace {

struct InfoArgs {
  std::string input, layout, json;
};

nlohmann::json channel_stats(const cv::Mat& img) {
  std::vector<double> lo(3, INFINITY), hi(3, -INFINITY), sum(3, 0.0);
  long finite = 0;
  for (int r = 0; r < img.rows; ++r) {
    const float* p = img.ptr<float>(r);
    for (int c = 0; c < img.cols; ++c, p += 3) {
      if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2])) continue;
      ++finite;
      for (int k = 0; k < 3; ++k) {
        lo[std::size_t(k)] = std::min(lo[std::size_t(k)], double(p[k]));
        hi[std::size_t(k)] = std::max(hi[std::size_t(k)], double(p[k]));
        sum[std::size_t(k)] += p[k];
      }
    }
  }
  nlohmann::json j;
  for (int k = 0; k < 3; ++k) {
    const char* name = k == 0 ? "R" : k == 1 ? "G" : "B";
    j[name] = {{"min", finite ? lo[std::size_t(k)] : 0.0},
               {"max", finite ? hi[std::size_t(k)] : 0.0},
               {"mean", finite ? sum[std::size_t(k)] / double(finite) : 0.0}};
  }
  return j;
}

int info_environment(const InfoArgs& a) {
  const std::optional<LayoutKind> hint =
      a.layout.empty() ? std::nullopt : std::optional<LayoutKind>(parse_layout_kind(a.layout));
  EnvReadReport rep;
  const EnvMap env = read_environment(a.input, hint, &rep);
  const cv::Mat sa = texel_solid_angles(env.layout);

  // Luminance distribution: the brightest texel and how much of the total it and its peers hold.
  double total = 0, peak = -INFINITY;
  int pc = 0, pr = 0;
  std::vector<double> lums;
  lums.reserve(std::size_t(env.layout.texel_count()));
  for (int r = 0; r < env.pixels.rows; ++r)
    for (int c = 0; c < env.pixels.cols; ++c) {
      const float* p = env.pixels.ptr<float>(r) + 3 * c;
      const double w = sa.at<double>(r, c);
      if (!(w > 0)) continue;
      const double Y = luminance(p);
      if (!std::isfinite(Y)) continue;
      lums.push_back(Y);
      total += std::max(0.0, Y) * w;
      if (Y > peak) {
        peak = Y;
        pc = c;
        pr = r;
      }
    }
  std::vector<double> sorted = lums;
  std::nth_element(sorted.begin(), sorted.begin() + long(sorted.size() / 2), sorted.end());
  const double median = sorted.empty() ? 0.0 : sorted[sorted.size() / 2];
  const Vec3 peak_dir = env.layout.direction(Vec2(pc, pr)).value_or(Vec3::Zero());
  const std::vector<double> integ = integral(env);

  nlohmann::json j;
  j["file"] = a.input;
  j["kind"] = "environment";
  j["format"] = rep.format;
  j["layout"] = to_string(env.layout.kind());
  j["layout_source"] = rep.layout_source;
  j["width"] = env.layout.width();
  j["height"] = env.layout.height();
  j["stored_channels"] = rep.channels;
  j["compression"] = rep.compression;
  j["colour"] = rep.chromaticities_converted ? "converted from the file's chromaticities to linear Rec.709 D65"
                                             : "linear Rec.709 D65";
  j["values"] = channel_stats(env.pixels);
  j["nan"] = rep.texels.nan;
  j["inf"] = rep.texels.inf;
  j["huge"] = rep.texels.huge;
  j["negative"] = rep.texels.negative;
  j["integral_rgb"] = integ;
  j["mean_radiance_rgb"] = {integ[0] / (4 * kPi), integ[1] / (4 * kPi), integ[2] / (4 * kPi)};
  j["peak"] = {{"luminance", peak},
               {"pixel", {pc, pr}},
               {"direction", {peak_dir.x(), peak_dir.y(), peak_dir.z()}},
               {"share_of_luminance_integral", total > 0 ? std::max(0.0, peak) * sa.at<double>(pr, pc) / total : 0.0}};
  j["median_luminance"] = median;
  j["dynamic_range"] = median > 0 ? peak / median : INFINITY;
  j["attributes"] = env.attributes;

  // With --json - stdout carries the JSON alone.
  std::ostream& text = a.json == "-" ? std::cerr : std::cout;
  text << a.input << ": " << to_string(env.layout.kind()) << " " << env.layout.width() << "x" << env.layout.height()
       << " (" << rep.layout_source << "), " << rep.format << " " << rep.channels << ", compression " << rep.compression
       << "\n"
       << "  colour:   " << j["colour"].get<std::string>() << "\n";
  for (const char* ch : {"R", "G", "B"})
    text << "  " << ch << ":        min " << j["values"][ch]["min"].get<double>() << "  max "
         << j["values"][ch]["max"].get<double>() << "  mean " << j["values"][ch]["mean"].get<double>() << "\n";
  text << "  mean radiance (solid-angle weighted) " << integ[0] / (4 * kPi) << " " << integ[1] / (4 * kPi) << " "
       << integ[2] / (4 * kPi) << "\n"
       << "  peak luminance " << peak << " at pixel (" << pc << ", " << pr << "), direction (" << peak_dir.x() << ", "
       << peak_dir.y() << ", " << peak_dir.z() << "); median " << median << "; dynamic range "
       << j["dynamic_range"].get<double>() << "\n"
       << "  suspicious values: " << rep.texels.nan << " NaN, " << rep.texels.inf << " Inf, " << rep.texels.huge
       << " beyond " << kMaxRadiance << ", " << rep.texels.negative << " negative"
       << (rep.texels.negative ? " (lossy-compression ringing? see --sanitize in convert)" : "") << "\n";
  for (const auto& [k, v] : env.attributes) text << "  rsibr." << k << ": " << v << "\n";
  write_summary(a.json, j);
  return 0;
}

int info_map_set(const InfoArgs& a) {
  // info describes what is there: unusable values are counted (read as --sanitize would), not refused.
  long unusable = 0;
  const MapSet set = read_map_set(a.input, BadTexels::zero, &unusable);
  const ViewSet vs = set.view_set();
  nlohmann::json j;
  j["file"] = a.input;
  j["kind"] = "map set";
  j["unusable_values"] = unusable;
  j["views"] = set.views.size();
  j["width"] = set.width();
  j["height"] = set.height();
  j["triangles"] = vs.triangles().size();
  j["surrounds_sphere"] = vs.surrounds();
  j["colour"] = "linear Rec.709 D65";
  std::ostream& text = a.json == "-" ? std::cerr : std::cout;
  text << a.input << ": map set, " << set.views.size() << " views of " << set.width() << "x" << set.height()
       << ", linear Rec.709 D65, " << vs.triangles().size() << " triangles, "
       << (vs.surrounds() ? "surrounds the sphere" : "does not surround the sphere") << "\n";
  if (unusable)
    text << "  " << unusable << " values that are NaN, Inf, beyond " << kMaxRadiance
         << ", negative, or confidences outside [0, 1]: --sanitize zeroes them (the other verbs refuse the "
            "non-finite, huge and out-of-range ones without it)\n";
  nlohmann::json views = nlohmann::json::array();
  for (std::size_t i = 0; i < set.views.size(); ++i) {
    const MapView& v = set.views[i];
    nlohmann::json jv;
    jv["view"] = {v.view.x(), v.view.y(), v.view.z()};
    nlohmann::json T = nlohmann::json::array();
    for (int r = 0; r < 3; ++r)
      T.push_back({v.world_from_view(r, 0), v.world_from_view(r, 1), v.world_from_view(r, 2)});
    jv["world_from_view"] = T;
    jv["channels"] = v.confidence.empty() ? "R G B" : "R G B confidence";
    jv["warp"] = to_string(v.warp);
    jv["source"] = to_string(v.source);
    jv["material"] = v.material;
    if (!v.image.empty()) jv["image"] = v.image;
    jv["confidence"] = !v.confidence.empty();
    jv["albedo_normalised"] = !v.albedo.empty();
    if (!v.albedo.empty()) jv["albedo_table"] = v.albedo;
    jv["values"] = channel_stats(v.rgb);
    jv["attributes"] = v.attributes;
    std::ostringstream line;
    line << std::fixed << std::setprecision(4) << "  view." << std::setw(3) << std::setfill('0') << i
         << std::setfill(' ') << "  v=(" << v.view.x() << ", " << v.view.y() << ", " << v.view.z() << ")  up=("
         << v.world_from_view(0, 1) << ", " << v.world_from_view(1, 1) << ", " << v.world_from_view(2, 1) << ")  "
         << to_string(v.warp) << "  " << to_string(v.source) << (v.confidence.empty() ? "" : "  +confidence")
         << (v.albedo.empty() ? "" : "  albedo-normalised");
    const std::string first_line = v.material.substr(0, v.material.find('\n'));
    if (!first_line.empty()) line << "  material: " << first_line;
    text << line.str() << "\n";
    views.push_back(jv);
  }
  j["parts"] = views;
  write_summary(a.json, j);
  return 0;
}

}  // namespace

Runner add_info(CLI::App& app) {
  auto a = std::make_shared<InfoArgs>();
  CLI::App* c = app.add_subcommand("info", "Show the header and a value summary of an environment map or a map set");
  c->footer(
      "For an environment: layout, channels, compression, colour, per-channel range, NaN/Inf/negative counts, "
      "mean radiance, peak and dynamic range. For a map set: views, frames, warp, source, material.");
  c->add_option("input", a->input, "Environment (.exr, .hdr) or map set (.exr)")->required();
  c->add_option("--layout", a->layout, "Layout of an environment whose header and shape do not tell");
  c->add_option("--json", a->json, "Write a JSON summary to FILE ('-' for stdout)");
  return [a] {
    OutputPlan outputs({a->input});
    InfoArgs b = *a;
    b.json = outputs.file(a->json);
    const int status = is_map_set_file(a->input) ? info_map_set(b) : info_environment(b);
    outputs.commit();
    return status;
  };
}

}  // namespace rsibr::cli
