// rsibr compare: two map sets (captured against computed, or any two), or two environments;
// metrics per view and overall before and after a global exposure / white-balance fit, heat maps
// and side-by-side pictures.
#include "cli/summary.h"
#include "cli/verbs.h"

#include "formats/atomic_file.h"
#include "formats/atomic_folder.h"
#include "compare/compare_pictures.h"
#include "compare/comparison_report.h"
#include "formats/exr_io.h"
#include "compare/map_compare.h"
#include "formats/input_file.h"
#include "formats/output_plan.h"
#include "core/preview_exposure.h"
#include "core/progress.h"

#include "formats/image_codecs.h"

#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>

namespace rsibr::cli {
namespace {

struct CompareArgs {
  std::string a, b, out, json, layout;
  bool no_fit = false, quiet = false, sanitize = false;
  double log_eps = 1e-2, psnr_peak = 0, view_tolerance = 0.5, loss_scale = 0.1, heat_max = 0, fail_above = 0;
  float exposure = NAN;
  long fit_texels = 1 << 17;
};

std::string direction_text(const Vec3& v) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(3) << "(" << v.x() << ", " << v.y() << ", " << v.z() << ")";
  return s.str();
}

std::string metrics_text(const ErrorMetrics& m) {
  std::ostringstream s;
  s << std::setprecision(4) << "rel RMS " << std::setw(10) << m.relative_rms << "  log RMS " << std::setw(10)
    << m.log_rms_stops << " stops  PSNR " << std::setprecision(4) << std::setw(7) << m.psnr_db << " dB"
    << (m.psnr_capped ? " (cap)" : "");
  return s.str();
}

std::vector<unsigned char> encode_png(const cv::Mat& bgr, const std::string& name) {
  std::vector<unsigned char> bytes;
  if (!encode_image(".png", bgr, bytes)) throw std::runtime_error(name + ": cannot encode the PNG");
  return bytes;
}

int run_compare(const CompareArgs& a) {
  namespace fs = std::filesystem;
  OutputPlan outputs({a.a, a.b});
  if (!a.out.empty()) {
    check_output_folder(a.out, {a.a, a.b});
    outputs.folder(a.out);
  }
  const std::string json = outputs.file(a.json);

  CompareOptions o;
  o.name_a = a.a;
  o.name_b = a.b;
  o.log_epsilon_fraction = a.log_eps;
  o.psnr_peak = a.psnr_peak;
  o.view_tolerance_deg = a.view_tolerance;
  o.fit = !a.no_fit;
  o.fit_options.loss_scale = a.loss_scale;
  o.fit_options.max_texels = a.fit_texels;

  // A missing or unreadable input is named as such, before either is classified.
  require_regular_file(a.a);
  require_regular_file(a.b);
  const bool set_a = is_map_set_file(a.a), set_b = is_map_set_file(a.b);
  if (set_a != set_b)
    throw std::invalid_argument((set_a ? a.b : a.a) + ": is an environment but " + (set_a ? a.a : a.b) +
                                " is a map set; compare a map set with a map set, an environment with an environment");
  Comparison c;
  std::string kind;
  long sanitized = 0;
  if (set_a) {
    kind = "map set";
    const BadTexels bad = a.sanitize ? BadTexels::zero : BadTexels::refuse;
    long za = 0, zb = 0;
    const MapSet ma = read_map_set(a.a, bad, &za), mb = read_map_set(a.b, bad, &zb);
    sanitized = za + zb;
    c = compare_map_sets(ma, mb, o);
  } else {
    kind = "environment";
    const std::optional<LayoutKind> hint =
        a.layout.empty() ? std::nullopt : std::optional<LayoutKind>(parse_layout_kind(a.layout));
    EnvMap ea = read_environment(a.a, hint), eb = read_environment(a.b, hint);
    for (auto [path, env] : {std::pair<const std::string*, EnvMap*>{&a.a, &ea}, {&a.b, &eb}}) {
      const TexelAudit audit = audit_texels(env->pixels);
      if (audit.bad() && !a.sanitize)
        throw std::runtime_error(*path + ": " + audit.describe() + "; pass --sanitize to zero them");
      if (a.sanitize) sanitized += sanitize_texels(env->pixels);
    }
    c = compare_environments(ea, eb, o);
  }

  // Heat maps of the error after the fit (the errors of shape), one scale for every view.
  const ComparisonImages images = comparison_images(c, a.heat_max, a.exposure);
  const double heat_max = images.heat_max;

  nlohmann::json j = comparison_json(c, images, kind == "map set");
  j["a"] = a.a;
  j["values_sanitized"] = sanitized;
  j["b"] = a.b;
  j["kind"] = kind;
  j["settings"]["log_epsilon_fraction_of_median_b"] = a.log_eps;
  j["settings"]["psnr_peak_source"] = a.psnr_peak > 0 ? "--psnr-peak" : "largest weighted value of B";
  j["settings"]["view_tolerance_deg"] = a.view_tolerance;
  j["settings"]["weights"] = kind == "map set" ? "texel centre inside the disc x confidence of A and B"
                                               : "sphere layout: disc; other layouts: texel solid angle";
  if (c.fit) j["fit"]["loss_scale"] = a.loss_scale;

  FolderContents files;
  std::vector<cv::Mat> panels;
  auto bar = std::make_shared<Progress>("compare", !a.quiet && Progress::stderr_is_terminal());
  for (std::size_t i = 0; i < c.pairs.size(); ++i) {
    const PairComparison& p = c.pairs[i];
    if (!a.out.empty()) {
      const std::string title = p.name + (kind == "map set" ? "  view " + direction_text(p.view) : "") + "   log RMS " +
                                std::to_string(p.after.log_rms_stops).substr(0, 6) + " stops";
      const cv::Mat panel = comparison_panel(c, images, i, title, c.fit ? "A x fitted gains" : "A", "B");
      const std::string name = p.name + ".png";
      files[name] = encode_png(panel, (fs::path(a.out) / name).string());
      j["views"][i]["picture"] = (fs::path(a.out) / name).string();
      panels.push_back(panel);
    }
    bar->update(double(i + 1) / double(c.pairs.size()));
  }
  bar->done();
  if (!a.out.empty()) {
    files["contact.png"] = encode_png(contact_sheet(panels), (fs::path(a.out) / "contact.png").string());
    j["contact_sheet"] = (fs::path(a.out) / "contact.png").string();
  }

  std::ostream& text = a.json == "-" ? std::cerr : std::cout;
  if (!a.quiet) {
    text << "rsibr compare: " << c.pairs.size() << (kind == "map set" ? " views" : " environment") << ", eps "
         << c.settings.log_epsilon << ", PSNR peak " << c.settings.psnr_peak << "\n";
    for (const PairComparison& p : c.pairs) {
      const std::string head = "  " + p.name + (kind == "map set" ? " " + direction_text(p.view) : "");
      text << head << "  before: " << metrics_text(p.before) << "\n"
           << std::string(head.size(), ' ') << "  after:  " << metrics_text(p.after) << "\n";
    }
    text << "  overall  before: " << metrics_text(c.before) << "\n  overall  after:  " << metrics_text(c.after) << "\n";
    if (c.fit)
      text << "  fitted gains (A -> B) " << c.fit->gains[0] << " " << c.fit->gains[1] << " " << c.fit->gains[2]
           << ": exposure " << c.fit->exposure_stops << " stops, chroma " << c.fit->chroma[0] << " " << c.fit->chroma[1]
           << " " << c.fit->chroma[2] << (c.fit->converged ? "" : " (not converged)") << "\n";
    if (!a.out.empty()) text << "  pictures in " << a.out << " (heat scale 0.." << heat_max << " stops)\n";
  }
  // The summary is written first, to its temporary: the pictures and the summary appear together.
  write_summary(json, j);
  if (!a.out.empty()) write_folder_atomically(a.out, files);
  outputs.commit();
  if (a.fail_above > 0 && c.after.log_rms_stops > a.fail_above) {
    std::cerr << "rsibr compare: " << a.a << ": log RMS error after the fit " << c.after.log_rms_stops
              << " stops exceeds --fail-above " << a.fail_above << "\n";
    return 3;
  }
  return 0;
}

}  // namespace

Runner add_compare(CLI::App& app) {
  auto a = std::make_shared<CompareArgs>();
  CLI::App* c = app.add_subcommand("compare", "Compare two map sets (captured vs computed) or two environments");
  c->footer(
      "B is the reference. Map sets: views are paired by direction (every view of the smaller set needs a view "
      "of the other within --view-tolerance; where the frames differ, e.g. a captured view's roll, B is resampled "
      "into A's frame); texels count inside the sphere-map disc, "
      "weighted by each map's confidence channel. Environments: same layout and size; sphere layouts weigh the "
      "disc, others solid angle.\n"
      "Metrics per view and overall: relative RMS sqrt(sum w|a-b|^2 / sum w|b|^2); log RMS in stops of "
      "log2((a+eps)/(b+eps)), eps = --log-eps x B's weighted median level; PSNR against B's largest weighted value "
      "(or --psnr-peak), capped at 144.5 dB (float32). Each is reported before and after a global gain fit "
      "g_c a_c ~ b_c (Ceres, Cauchy loss) that separates exposure and white balance from errors of shape.\n"
      "--out DIR gets view.NNN.png or environment.png (A x gains | B | heat map of the log2 error after the fit, with a scale "
      "bar) and contact.png, all or nothing. Exit status: 0 done, 3 when --fail-above is exceeded, other "
      "non-zero values on errors.\n"
      "Example: rsibr compare captured.exr computed.exr --out cmp --json cmp.json");
  c->add_option("a", a->a, "Map set or environment A (e.g. captured)")->required();
  c->add_option("b", a->b, "Map set or environment B, the reference (e.g. computed)")->required();
  c->add_option("--out", a->out, "Folder for the pictures (created if missing; its parent must exist)");
  c->add_option("--json", a->json, "Write the metrics as JSON to FILE ('-' for stdout)");
  c->add_flag("--no-fit", a->no_fit, "Skip the exposure / white-balance fit (after = before)");
  c->add_option("--log-eps", a->log_eps, "eps of the log error as a fraction of B's weighted median (default 0.01)")
      ->check(CLI::Range(1e-9, 1e3));
  c->add_option("--psnr-peak", a->psnr_peak, "Peak of the PSNR (default: B's largest weighted value)")
      ->check(CLI::PositiveNumber);
  c->add_option("--view-tolerance", a->view_tolerance, "Largest angle in degrees between paired views (default 0.5)")
      ->check(CLI::Range(0.0, 90.0));
  c->add_option("--loss-scale", a->loss_scale, "Cauchy loss scale of the fit in ln units (default 0.1, about 10 %)")
      ->check(CLI::Range(1e-6, 1e6));
  c->add_option("--fit-texels", a->fit_texels, "At most this many texels enter the fit (every n-th; 0: all)")
      ->check(CLI::Range(0L, 1L << 30));
  c->add_option("--heat-max", a->heat_max, "Top of the heat-map scale in stops (default: the 99th percentile)")
      ->check(CLI::PositiveNumber);
  c->add_option("--exposure", a->exposure, "Display exposure of A and B in stops (default: B's mean at 0.18)");
  c->add_option("--layout", a->layout, "Layout of environments whose header and shape do not tell");
  c->add_option("--fail-above", a->fail_above,
                "Exit with status 3 when the overall log RMS after the fit exceeds this (stops)")
      ->check(CLI::PositiveNumber);
  c->add_flag("--sanitize", a->sanitize,
              "Zero NaN, Inf and absurd (> 1e30) values of the map sets (and clamp their "
              "confidences to [0, 1]) instead of failing; the JSON counts them");
  c->add_flag("-q,--quiet", a->quiet, "No progress bar or report");
  return [a] { return run_compare(*a); };
}

}  // namespace rsibr::cli
