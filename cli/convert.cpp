// rsibr convert: an environment map from one layout and size to another.
#include "cli/summary.h"
#include "formats/file_error.h"
#include "cli/verbs.h"

#include "formats/atomic_file.h"
#include "core/colour.h"
#include "formats/exr_io.h"
#include "formats/output_plan.h"
#include "core/preview_exposure.h"
#include "core/progress.h"
#include "core/resample.h"

#include "formats/image_codecs.h"

#include <chrono>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>

namespace rsibr::cli {
namespace {

struct ConvertArgs {
  std::string input, output, to, from_layout, preview, json, input_colour_space;
  int size = 0;
  int max_subsamples = 32;
  double supersampling = 4.0;
  double energy_tolerance = 1e-4;
  bool half = false, sanitize = false, quiet = false;
  std::optional<float> preview_exposure;  // nullopt: metered (core/preview_exposure.h)
};

// The size in the target layout whose texel count matches the input's (same mean texel solid angle).
int matching_size(LayoutKind kind, long texels) {
  const double t = double(texels);
  switch (kind) {
    case LayoutKind::LatLong: return std::max(4, int(std::lround(std::sqrt(2 * t))));
    case LayoutKind::Cube: return std::max(2, int(std::lround(std::sqrt(t / 6))));
    case LayoutKind::Octahedral: return std::max(2, 2 * int(std::lround(std::sqrt(t) / 2)));
    case LayoutKind::Sphere: return std::max(2, int(std::lround(std::sqrt(4 * t / kPi))));
  }
  return 0;
}

std::string command_line_text(const ConvertArgs& a, const Layout& dst) {
  return "rsibr convert " + std::filesystem::path(a.input).filename().string() + " --to " + to_string(dst.kind()) +
         " --size " + std::to_string(dst.size());
}

int run_convert(const ConvertArgs& a) {
  if (std::filesystem::path(a.output).extension() != ".exr")
    throw std::invalid_argument(a.output + ": the output must be an .exr file (use --preview for a PNG)");
  OutputPlan outputs({a.input});
  const std::string exr = outputs.file(a.output), preview = outputs.file(a.preview), json = outputs.file(a.json);
  const std::optional<LayoutKind> hint =
      a.from_layout.empty() ? std::nullopt : std::optional<LayoutKind>(parse_layout_kind(a.from_layout));
  const LayoutKind to = parse_layout_kind(a.to);

  const auto t0 = std::chrono::steady_clock::now();
  EnvReadReport report;
  EnvMap src = read_environment(a.input, hint, &report);
  if (!a.input_colour_space.empty()) convert_colour_space(src.pixels, a.input_colour_space, working_space());
  if (report.texels.bad() && !a.sanitize)
    throw std::runtime_error(a.input + ": " + report.texels.describe() + "; pass --sanitize to zero them");
  const long sanitized = a.sanitize ? sanitize_texels(src.pixels) : 0;
  // A converter keeps values as they are unless asked; negative ones are said out loud.
  if (!a.sanitize && report.texels.negative > 0)
    std::cerr << "rsibr convert: warning: " << a.input << ": " << report.texels.negative
              << " negative values (lossy-compression ringing) kept; --sanitize folds them into their positive "
                 "neighbours, energy kept\n";
  const auto t1 = std::chrono::steady_clock::now();

  const int size = a.size > 0 ? a.size : matching_size(to, src.layout.texel_count());
  const Layout dst = Layout::with_size(to, size);
  ResampleOptions options;
  options.max_subsamples = a.max_subsamples;
  options.supersampling = a.supersampling;
  options.energy_tolerance = a.energy_tolerance;
  auto bar = std::make_shared<Progress>("convert", !a.quiet && Progress::stderr_is_terminal());
  options.progress = [bar](double f) { bar->update(f); };
  EnvMap out = resample(src, dst, options);
  bar->done();
  const auto t2 = std::chrono::steady_clock::now();

  out.attributes["version"] = RSIBR_VERSION;
  out.attributes["input"] = std::filesystem::path(a.input).filename().string();
  out.attributes["command"] = command_line_text(a, dst);
  ExrWriteOptions wo;
  wo.half = a.half;
  write_environment(exr, out, wo);
  if (!preview.empty() &&
      !write_image(preview,
                   display_encode(out.pixels, a.preview_exposure ? *a.preview_exposure : preview_exposure(out.pixels))))
    throw FileError(a.preview, "cannot write the preview image", {}, FileRole::Output);
  const auto t3 = std::chrono::steady_clock::now();

  const std::vector<double> in_int = integral(src), out_int = integral(out);
  double rel = 0;
  for (int k = 0; k < 3; ++k)
    rel = std::max(rel, std::abs(out_int[std::size_t(k)] - in_int[std::size_t(k)]) /
                            std::max(1e-30, std::abs(in_int[std::size_t(k)])));
  auto secs = [](auto d) { return std::chrono::duration<double>(d).count(); };
  if (!a.quiet)
    std::cerr << "rsibr convert: " << to_string(src.layout.kind()) << " " << src.layout.width() << "x"
              << src.layout.height() << " -> " << to_string(dst.kind()) << " " << dst.width() << "x" << dst.height()
              << ", integral change " << rel << " (relative, worst channel), resample " << secs(t2 - t1) << " s\n";
  nlohmann::json j;
  j["input"] = a.input;
  j["output"] = a.output;
  j["from"] = {{"layout", to_string(src.layout.kind())},
               {"width", src.layout.width()},
               {"height", src.layout.height()},
               {"layout_source", report.layout_source},
               {"compression", report.compression}};
  j["to"] = {{"layout", to_string(dst.kind())}, {"width", dst.width()}, {"height", dst.height()}};
  j["integral_in"] = in_int;
  j["integral_out"] = out_int;
  j["integral_relative_change"] = rel;
  j["values_sanitized"] = sanitized;
  j["seconds"] = {{"read", secs(t1 - t0)}, {"resample", secs(t2 - t1)}, {"write", secs(t3 - t2)}};
  write_summary(json, j);
  outputs.commit();
  return 0;
}

}  // namespace

Runner add_convert(CLI::App& app) {
  auto a = std::make_shared<ConvertArgs>();
  CLI::App* c = app.add_subcommand("convert", "Convert an environment map between layouts and sizes");
  c->footer(
      "Layouts: latlong (OpenEXR LatLongMap), cube (OpenEXR CubeMap, W x 6W), octahedral (square, +Y at the "
      "centre), sphere (mirror ball seen from +Z). Shrinking is area-weighted (no aliasing); enlarging is "
      "bilinear. The solid-angle-weighted integral of the input and output is reported.\n"
      "Example: rsibr convert sky.exr sky-cube.exr --to cube --size 256 --preview sky-cube.png");
  c->add_option("input", a->input, "Environment map (.exr, or Radiance .hdr)")->required();
  c->add_option("output", a->output, "Output .exr (written atomically; never the input)")->required();
  c->add_option("--to", a->to, "Target layout: latlong, cube, octahedral or sphere")->required();
  c->add_option("--size", a->size,
                "Target size: lat-long width, cube face, octahedral/sphere side (default: same texel count as "
                "the input)")
      ->check(CLI::Range(2, 32768));
  c->add_option("--layout", a->from_layout, "Layout of the input when its header and shape do not tell");
  c->add_option("--input-colorspace", a->input_colour_space,
                "OpenColorIO colour space of the input pixels (default: the file's chromaticities; $OCIO honoured)");
  c->add_flag("--half", a->half, "Write half floats (an error if a value exceeds 65504)");
  c->add_flag("--sanitize", a->sanitize,
              "Zero NaN, Inf and absurd input values; fold negative ones (lossy-compression ringing) into their "
              "positive neighbours, the integral kept");
  c->add_option("--supersampling", a->supersampling,
                "Taps per source texel across an output texel's footprint (1: area sampling; default 4 keeps a "
                "one-texel sun's energy to ~1e-3)")
      ->check(CLI::Range(1.0, 16.0));
  c->add_option("--energy-tolerance", a->energy_tolerance,
                "Energy budget per texel relative to the map's (extra taps where the input is far brighter than "
                "its mean, e.g. a sun; 0 disables)")
      ->check(CLI::Range(0.0, 1.0));
  c->add_option("--max-subsamples", a->max_subsamples, "Cap on n for the n x n taps per output texel")
      ->check(CLI::Range(1, 64));
  c->add_option("--preview", a->preview, "Also write a display-encoded PNG of the output");
  c->add_option("--preview-exposure", a->preview_exposure,
                "Exposure of the preview in stops (default: the median luminance at mid-grey)");
  c->add_option("--json", a->json, "Write a JSON summary to FILE ('-' for stdout)");
  c->add_flag("-q,--quiet", a->quiet, "No progress bar or report line");
  return [a] { return run_convert(*a); };
}

}  // namespace rsibr::cli
