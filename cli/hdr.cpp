// rsibr hdr: merge each view's exposure brackets into radiance (hdr/): exposures from
// photoset.yaml or EXIF, a response curve recovered (model chosen by held-out error) or reused,
// a shot + read noise model, the inverse-variance merge with variance, clipped, black and ghost
// channels, conversion to the working colour space, EXR + PNG preview per view.
#include "cli/summary.h"
#include "formats/file_error.h"
#include "cli/verbs.h"

#include "formats/atomic_file.h"
#include "formats/atomic_folder.h"
#include "core/colour.h"
#include "formats/output_plan.h"
#include "formats/photo_set.h"
#include "core/preview_exposure.h"
#include "core/progress.h"
#include "core/text.h"
#include "hdr/alignment.h"
#include "hdr/bracket_set.h"
#include "hdr/merge.h"
#include "hdr/merged_colour.h"
#include "hdr/merged_exr.h"
#include "hdr/noise_model.h"
#include "hdr/photo_set_merge.h"
#include "hdr/response_recovery.h"
#include "pipeline/vignetting_input.h"
#include "calib/lens/far_camera.h"

#include "formats/image_codecs.h"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <optional>
#include <sstream>

namespace rsibr::cli {
namespace {

namespace fs = std::filesystem;

struct HdrArgs {
  std::string photoset, out, response, model = "auto", channels = "auto", noise, input_colour_space, json, saturation,
                                       white_balance, vignetting = "auto", lens;
  std::vector<std::string> views;
  int samples = 20000;
  double smoothness = 1000.0, ghost_sigmas = -1;
  bool align = false, no_align = false, deghost = false, quiet = false, no_preview = false;
  std::optional<float> preview_exposure;
};

std::string join(const std::vector<double>& v) {
  std::ostringstream s;
  s.precision(9);
  for (std::size_t i = 0; i < v.size(); ++i) s << (i ? " " : "") << v[i];
  return s.str();
}

NoiseModel parse_noise(const std::string& text) {
  NoiseModel n;
  double shot = 0, read = 0;
  char comma = 0;
  std::istringstream in(text);
  if (!(in >> shot >> comma >> read) || comma != ',' || !(in >> std::ws).eof() || !(shot >= 0) || !(read > 0) ||
      !std::isfinite(shot) || !std::isfinite(read))
    throw std::invalid_argument("--noise '" + text +
                                "': expected SHOT,READ with SHOT >= 0 and READ > 0 (variance = SHOT * X + READ)");
  n.shot = {shot, shot, shot};
  n.read = {read, read, read};
  n.source = "given";
  return n;
}

// "N" (every channel) or "R,G,B": codes, each in (0, max_code] once the bit depth is known.
std::array<int, 3> parse_saturation(const std::string& text) {
  std::array<int, 3> out{-1, -1, -1};
  if (text.empty()) return out;
  std::istringstream in(text);
  std::vector<int> v;
  for (std::string item; std::getline(in, item, ',');) {
    try {
      std::size_t used = 0;
      const int code = std::stoi(item, &used);
      if (used != item.size() || code <= 0) throw std::invalid_argument("");
      v.push_back(code);
    } catch (const std::exception&) {
      throw std::invalid_argument("--saturation-code '" + text + "': expected N or R,G,B, positive codes");
    }
  }
  if (v.size() == 1) v.assign(3, v[0]);
  if (v.size() != 3) throw std::invalid_argument("--saturation-code '" + text + "': expected N or R,G,B");
  for (int c = 0; c < 3; ++c) out[std::size_t(c)] = v[std::size_t(c)];
  return out;
}

// "R,G,B" positive gains.
std::optional<cv::Vec3f> parse_gains(const std::string& text) {
  if (text.empty() || text == "camera") return std::nullopt;
  cv::Vec3f g;
  char c1 = 0, c2 = 0;
  std::istringstream in(text);
  if (!(in >> g[0] >> c1 >> g[1] >> c2 >> g[2]) || c1 != ',' || c2 != ',' || !(in >> std::ws).eof() ||
      !(g[0] > 0 && g[1] > 0 && g[2] > 0) || !std::isfinite(g[0] + g[1] + g[2]))
    throw std::invalid_argument("--white-balance '" + text + "': expected camera or R,G,B positive gains");
  return g;
}

std::string describe(const NoiseModel& n) {
  std::ostringstream s;
  s.precision(4);
  s << "var(X) = shot*X + read + (1/12 + code + texture a^2) step^2 (" << n.source << "); shot " << n.shot[0] << " "
    << n.shot[1] << " " << n.shot[2] << "; read " << n.read[0] << " " << n.read[1] << " " << n.read[2] << "; code "
    << n.code[0] << " " << n.code[1] << " " << n.code[2] << "; texture " << n.texture[0] << " " << n.texture[1] << " "
    << n.texture[2];
  return s.str();
}

// Preview exposure: the median luminance of unclipped pixels maps to 0.18.
float unclipped_exposure(const MergedImage& m) {
  cv::Mat unclipped;
  cv::bitwise_and(m.flags, cv::Scalar(kClipped), unclipped);
  return preview_exposure(m.radiance, unclipped == 0);
}

std::string relative_name(const fs::path& file, const fs::path& folder) {
  const fs::path rel = file.lexically_relative(folder);
  return rel.empty() || *rel.begin() == ".." ? file.string() : rel.string();
}

int run_hdr(const HdrArgs& a) {
  const auto t_start = std::chrono::steady_clock::now();
  const PhotoSet set = load_photo_set(a.photoset);
  std::vector<const PhotoView*> views;
  if (a.views.empty())
    for (const PhotoView& v : set.views) views.push_back(&v);
  for (const std::string& name : a.views) {
    const auto it =
        std::find_if(set.views.begin(), set.views.end(), [&](const PhotoView& v) { return v.name == name; });
    if (it == set.views.end())
      throw std::invalid_argument(a.photoset + ": no view named '" + quoted_for_message(name) + "'");
    if (std::find(views.begin(), views.end(), &*it) != views.end())
      throw std::invalid_argument("--view: '" + quoted_for_message(name) + "' is given twice");
    views.push_back(&*it);
  }
  std::optional<NoiseModel> given_noise;
  if (!a.noise.empty()) given_noise = parse_noise(a.noise);
  const std::array<int, 3> given_saturation = parse_saturation(a.saturation);
  const std::optional<cv::Vec3f> gains = parse_gains(a.white_balance);
  if (a.channels != "auto" && a.channels != "shared" && a.channels != "separate")
    throw std::invalid_argument("--channels '" + a.channels + "': expected auto, shared or separate");
  std::optional<ResponseCurve> given_curve;
  if (!a.response.empty()) given_curve = load_response(a.response);
  if (a.model != "auto" && a.model != "identity" && a.model != "gamma" && a.model != "polynomial" &&
      a.model != "robertson" && a.model != "debevec")
    throw std::invalid_argument("--model '" + a.model +
                                "': expected auto, identity, gamma, polynomial, robertson or debevec");
  const std::string working = working_space();
  // The camera's colour space: --input-colorspace, else the photo set's camera.colour_space.
  const std::string input_space = !a.input_colour_space.empty() ? a.input_colour_space : set.camera_colour_space;
  if (!input_space.empty() && input_space != working) {
    try {
      colour_conversion_matrix(input_space, working);  // errors before any work
    } catch (const std::runtime_error& e) {
      throw std::invalid_argument(
          (a.input_colour_space.empty() ? a.photoset + ": camera.colour_space: " : "--input-colorspace: ") + e.what());
    }
  }

  // A vignetting file is read before any work (its model needs neither the response nor the lens).
  if (a.vignetting != "auto" && a.vignetting != "none")
    photo_set_vignetting(set, a.vignetting, ResponseCurve{}, LensModel::pinhole(1, 1, 1), nullptr);

  // Outputs: the folder may be new (its parent must exist); no output may name an input.
  const fs::path out_dir = fs::absolute(a.out);
  if (!fs::is_directory(out_dir)) {
    if (!fs::is_directory(out_dir.parent_path()))
      throw std::invalid_argument(a.out + ": neither it nor its parent folder exists");
  }
  std::vector<fs::path> inputs = set.files();
  if (!a.response.empty()) inputs.push_back(a.response);
  if (!a.lens.empty()) inputs.push_back(a.lens);
  for (const fs::path& f : vignetting_inputs(set, a.vignetting)) inputs.push_back(f);
  const std::optional<LensModel> given_lens = !a.lens.empty() ? std::optional<LensModel>(LensModel::read(a.lens))
                                              : set.camera_model
                                                  ? std::optional<LensModel>(LensModel::read(*set.camera_model))
                                                  : std::nullopt;
  OutputPlan outputs(inputs);
  outputs.folder(a.out);
  const std::string json = outputs.file(a.json);
  std::vector<std::pair<fs::path, fs::path>> staged;  // (temporary, final)
  const fs::path response_out = out_dir / "response.json";
  const fs::path vignetting_out = out_dir / "vignetting.json";
  for (const PhotoView* v : views)
    for (const char* ext : {".exr", ".png"}) {
      const fs::path target = file_in_folder(out_dir, v->name + ext);
      for (const fs::path& in : inputs) check_not_same_file(in, target);
    }
  for (const fs::path& in : inputs) check_not_same_file(in, response_out), check_not_same_file(in, vignetting_out);

  // Everything goes to a staging folder inside the output folder and is renamed into place only
  // when every view has merged: a failure leaves no partial output.
  const bool created_out = !fs::is_directory(out_dir);
  if (created_out) fs::create_directory(out_dir);
  const fs::path stage = out_dir / (".rsibr-hdr.tmp" + std::to_string(::getpid()));
  fs::create_directory(stage);
  nlohmann::json summary;
  try {
    Progress bar("hdr", !a.quiet && Progress::stderr_is_terminal());
    // The response: reused, or recovered once per photo set (one camera) from every view; the noise
    // model likewise from every view (unless given).
    RecoveryOptions ro;
    ro.model = a.model;
    ro.channels = a.channels;
    ro.samples = a.samples;
    ro.smoothness = a.smoothness;
    ro.saturation_code = given_saturation;
    ResponseCurve curve;
    nlohmann::json response_json;
    const Alignment alignment = a.align ? Alignment::always : a.no_align ? Alignment::off : Alignment::automatic;
    const PhotoSetResponse psr = recover_photo_set_response(views, ro, alignment, given_curve);
    const NoiseModel pooled_noise = given_noise ? *given_noise : psr.noise;
    nlohmann::json from = nlohmann::json::array();
    for (const PhotoView* v : psr.from) from.push_back(v->name);
    if (given_curve) {
      curve = *given_curve;
      for (int c = 0; c < 3; ++c)
        if (given_saturation[std::size_t(c)] > 0) curve.saturation[std::size_t(c)] = given_saturation[std::size_t(c)];
      response_json = {{"model", curve.model}, {"source", a.response}};
    } else {
      const ResponseRecovery& rec = psr.recovery;
      curve = rec.curve;
      response_json = recovery_json(rec);
      response_json["model"] = curve.model;
      response_json["parameters"] = curve.parameters;
      response_json["recovered_from"] = from;
      response_json["file"] = response_out.string();
      save_response(stage / "response.json", curve,
                    {{"camera", set.camera_name}, {"recovered_from", from}, {"recovery", recovery_json(rec)}});
      staged.push_back({stage / "response.json", response_out});
      if (rec.near_tie && !a.quiet) std::cerr << "rsibr hdr: warning: " << rec.warning << "\n";
    }
    for (int c = 0; c < 3; ++c)
      if (given_saturation[std::size_t(c)] > curve.max_code)
        throw std::invalid_argument("--saturation-code: " + std::to_string(given_saturation[std::size_t(c)]) +
                                    " is above the photos' top code " + std::to_string(curve.max_code));
    curve.validate();
    response_json["saturation_code"] = {curve.saturation_code(0), curve.saturation_code(1), curve.saturation_code(2)};
    response_json["noise"] = {{"source", pooled_noise.source}, {"views", pooled_noise.views},
                              {"shot", pooled_noise.shot},     {"read", pooled_noise.read},
                              {"code", pooled_noise.code},     {"texture", pooled_noise.texture}};
    response_json["white_balance"] =
        gains ? nlohmann::json({(*gains)[0], (*gains)[1], (*gains)[2]}) : nlohmann::json("camera");
    // A plot-friendly curve: 65 points per channel.
    nlohmann::json plot = nlohmann::json::array();
    for (int k = 0; k <= 64; ++k) {
      const double z = double(k) * curve.max_code / 64;
      plot.push_back({{"code", z}, {"X", {curve.linear(0, z), curve.linear(1, z), curve.linear(2, z)}}});
    }
    response_json["curve"] = plot;
    response_json["max_code"] = curve.max_code;
    summary["response"] = response_json;

    std::string response_model = curve.model;
    if (!given_curve) {
      std::ostringstream s;
      s.precision(3);
      s << psr.recovery.chosen;
      for (const auto& c : psr.recovery.candidates)
        if (c.tied && c.model == curve.model && c.shared == curve.parameters.value("shared", true)) {
          s << ", held-out code error " << c.held_out_error;
          break;
        }
      if (std::isfinite(psr.recovery.margin_sigmas)) s << ", margin " << psr.recovery.margin_sigmas << " sigma";
      if (psr.recovery.near_tie) s << " (near tie)";
      response_model = s.str();
    }

    // Vignetting, chosen as the hdr step of rsibr process chooses it (pipeline/vignetting_input.h),
    // about the lens's principal point: --lens, else the photo set's camera model, else the centre
    // of the photos (the first view's size).
    const LensModel lens = given_lens ? *given_lens : [&] {
      if (a.vignetting == "none") return LensModel::pinhole(1, 1, 1);
      const BracketSet first = load_brackets(*views.front(), alignment != Alignment::off);
      return LensModel::pinhole(std::hypot(double(first.cols()), double(first.rows())), first.cols(), first.rows());
    }();
    nlohmann::json vignetting_report;
    const Vignetting vignetting = photo_set_vignetting(set, a.vignetting, curve, lens, &vignetting_report);
    vignetting_report["principal_point_from"] = !a.lens.empty()    ? "--lens " + a.lens
                                                : set.camera_model ? "the photo set's camera model"
                                                                   : std::string("the image centre");
    summary["vignetting"] = vignetting_report;
    write_text_atomically(stage / "vignetting.json", vignetting_report["model"].dump(2) + "\n");
    staged.push_back({stage / "vignetting.json", vignetting_out});

    ViewMergeSettings vs;
    vs.noise = pooled_noise;
    vs.align = alignment;
    vs.merge.ghost_sigmas = a.ghost_sigmas;
    vs.merge.deghost = a.deghost;
    vs.vignetting = &vignetting;
    vs.white_balance = gains;
    vs.input_colour_space = a.input_colour_space;
    vs.camera_colour_space = set.camera_colour_space;
    nlohmann::json view_list = nlohmann::json::array();
    for (std::size_t vi = 0; vi < views.size(); ++vi) {
      const PhotoView& v = *views[vi];
      const auto t0 = std::chrono::steady_clock::now();
      ViewMerge vm = merge_view_radiance(v, curve, vs);
      const auto t1 = t0 + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                               std::chrono::duration<double>(vm.seconds_load));
      const BracketSet& b = vm.brackets;
      const std::vector<cv::Point>& shifts = vm.shifts;
      const NoiseModel& noise = vm.noise;
      MergedImage& m = vm.image;
      const std::string& from = vm.input_colour_space;
      // The model is in the lens's pixels: a given lens of another size than the photos is the
      // wrong one (unless it is a far camera's canvas for crops), and so is any lens the model
      // divides out about.
      const bool other_size = m.radiance.cols != lens.width() || m.radiance.rows != lens.height();
      if (other_size && (!vignetting.is_identity() || (given_lens && a.vignetting != "none" && !is_far_camera(lens))))
        throw std::invalid_argument(
            (given_lens ? (!a.lens.empty() ? a.lens : set.camera_model->string()) : std::string("the lens")) + ": " +
            std::to_string(lens.width()) + "x" + std::to_string(lens.height()) + " but view " + v.name +
            "'s photos are " + std::to_string(m.radiance.cols) + "x" + std::to_string(m.radiance.rows) +
            " (vignetting is about its principal point)");
      const auto t2 = std::chrono::steady_clock::now();
      std::string files;
      for (const std::string& f : b.files) files += (files.empty() ? "" : ";") + relative_name(f, set.folder);
      std::vector<double> times;
      std::string sources;
      for (const auto& md : b.metadata)
        times.push_back(md.exposure_s), sources += (sources.empty() ? "" : " ") + md.source;
      std::string shift_text;
      for (const auto& s : shifts)
        shift_text += (shift_text.empty() ? "" : " ") + std::to_string(s.x) + "," + std::to_string(s.y);
      const std::map<std::string, std::string> attrs = {
          {"version", RSIBR_VERSION},
          {"view", v.name},
          {"files", files},
          {"exposures", join(b.exposures)},
          {"exposureTimes", join(times)},
          {"exposureSource", sources},
          {"responseModel", response_model},
          {"responseFile", given_curve ? a.response : std::string("response.json (next to this file)")},
          {"noiseModel", describe(noise)},
          {"radianceUnit", "X/e: signal over saturation per relative exposure t*iso/100/N^2"},
          {"colourSpace", working},
          {"inputColourSpace", from.empty() ? working : from},
          {"alignment", alignment == Alignment::off ? "none"
                                                    : std::string("median threshold bitmaps, coarse to fine (") +
                                                          to_string(alignment) + "), shifts " + shift_text},
          {"ghosts", a.deghost ? "flagged; longest usable bracket alone" : "flagged; merged as usual"},
          {"vignetting", vignetting.is_identity() ? std::string("none") : vignetting.source + " (divided out)"},
          {"flags",
           "clipped: lower bound (saturated in every bracket); black: nothing recorded; ghost: brackets disagree"}};
      write_merged_exr(file_in_folder(stage, v.name + ".exr").string(), m, attrs);
      staged.push_back({stage / (v.name + ".exr"), file_in_folder(out_dir, v.name + ".exr")});
      const float stops = a.preview_exposure ? *a.preview_exposure : unclipped_exposure(m);
      if (!a.no_preview) {
        const cv::Mat png = display_encode(m.radiance, stops);
        const fs::path p = file_in_folder(stage, v.name + ".png");
        if (!write_image(p.string(), png))
          throw FileError(p.string(), "cannot write the preview", {}, FileRole::Output);
        staged.push_back({p, file_in_folder(out_dir, v.name + ".png")});
      }
      const auto t3 = std::chrono::steady_clock::now();
      auto secs = [](auto d) { return std::chrono::duration<double>(d).count(); };
      const double pixels = double(m.radiance.total());
      double lo = 0, hi = 0;
      cv::minMaxLoc(m.radiance.reshape(1), &lo, &hi);
      nlohmann::json vj = {{"name", v.name},
                           {"width", b.cols()},
                           {"height", b.rows()},
                           {"bit_depth", b.max_code == 255 ? 8 : 16},
                           {"files", b.files},
                           {"exposures", b.exposures},
                           {"exposure_s", times},
                           {"exposure_source", sources},
                           {"noise", {{"source", noise.source}, {"shot", noise.shot}, {"read", noise.read}}},
                           {"clipped_pixels", m.clipped},
                           {"clipped_fraction", m.clipped / pixels},
                           {"black_pixels", m.black},
                           {"ghost_pixels", m.ghost},
                           {"ghost_fraction", m.ghost / pixels},
                           {"radiance_min", lo},
                           {"radiance_max", hi},
                           {"preview_exposure_stops", stops},
                           {"exr", (out_dir / (v.name + ".exr")).string()},
                           {"seconds", {{"load", secs(t1 - t0)}, {"merge", secs(t2 - t1)}, {"write", secs(t3 - t2)}}}};
      if (b.raw) {
        // How LibRaw developed the RAW files (hdr/raw_image.h), per bracket.
        nlohmann::json rj = nlohmann::json::array();
        for (const RawInfo& ri : b.raw_info) {
          nlohmann::json M = nlohmann::json::array();
          for (int r = 0; r < 3; ++r)
            M.push_back({ri.rgb_from_camera(r, 0), ri.rgb_from_camera(r, 1), ri.rgb_from_camera(r, 2)});
          rj.push_back({{"camera", ri.make + " " + ri.model},
                        {"black", ri.black},
                        {"white", ri.white},
                        {"white_balance", {ri.white_balance[0], ri.white_balance[1], ri.white_balance[2]}},
                        {"rec709_from_camera", M},
                        {"saturated_fraction", ri.saturated_fraction}});
        }
        vj["raw"] = rj;
      }
      {
        nlohmann::json sj = nlohmann::json::array(), fj = nlohmann::json::array(), sizes = nlohmann::json::array();
        for (const auto& s : shifts) sj.push_back({s.x, s.y});
        for (const auto& s : vm.alignment.found) fj.push_back({s.x, s.y});
        for (const auto& s : b.file_sizes) sizes.push_back({s.width, s.height});
        vj["alignment"] = {{"mode", to_string(alignment)},
                           {"shifts", sj},
                           {"found", fj},
                           {"mismatch_before", vm.alignment.mismatch_before},
                           {"mismatch_after", vm.alignment.mismatch_after},
                           {"rotations_deg", vm.alignment.rotation_deg},
                           {"beyond_search", vm.alignment.beyond_search},
                           {"file_sizes", sizes},
                           {"sizes_fitted", b.fitted_sizes}};
        vj["alignment_shifts"] = sj;
      }
      view_list.push_back(vj);
      bar.update(double(vi + 1) / double(views.size()));
      if (!a.quiet)
        std::cerr << "rsibr hdr: " << v.name << ": " << b.size() << " brackets, " << b.cols() << "x" << b.rows()
                  << ", clipped " << m.clipped << ", ghost " << m.ghost << " pixels, merge " << secs(t2 - t1) << " s\n";
    }
    bar.done();
    summary["views"] = view_list;
    summary["photoset"] = set.folder.string();
    summary["output"] = out_dir.string();
    summary["colour_space"] = working;
    summary["radiance_unit"] = "X/e: linear signal normalised to saturation, per unit relative exposure t*iso/100/N^2";
    summary["seconds"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
    write_summary(json, summary);  // to its temporary: in place with the merged views, or not at all
    for (const auto& [tmp, target] : staged) fs::rename(tmp, target);
    fs::remove_all(stage);
  } catch (...) {
    std::error_code ec;
    fs::remove_all(stage, ec);
    if (created_out) fs::remove(out_dir, ec);
    throw;
  }
  outputs.commit();
  if (!a.quiet) std::cerr << "rsibr hdr: response model " << summary["response"]["model"].get<std::string>() << "\n";
  return 0;
}

}  // namespace

Runner add_hdr(CLI::App& app) {
  auto a = std::make_shared<HdrArgs>();
  CLI::App* c =
      app.add_subcommand("hdr", "Merge each view's exposure brackets into radiance (EXR with variance and flags)");
  c->footer(
      "For every view of the photo set: exposures from photoset.yaml (EXIF fills what it leaves out), the camera "
      "response (recovered once per photo set and written to OUT/response.json, or reused with --response), a "
      "shot + read noise model (estimated from the brackets, or --noise), and the inverse-variance merge. A bracket "
      "saturated in any channel is left out for that pixel; pixels saturated in every bracket are flagged 'clipped' "
      "and hold a lower bound. OUT/<view>.exr has R,G,B, variance.R/G/B, clipped, black, ghost; OUT/<view>.png is a "
      "preview; OUT/vignetting.json is the lens falloff divided out (--vignetting). Radiance unit: X/e, the signal over its saturation value per relative exposure t*iso/100/N^2. "
      "Photos: PNG, JPEG, TIFF, or camera RAW files (DNG, CR2, CR3, NEF, ARW, ... through LibRaw: linear, no response "
      "to recover, saturation from the file). Handheld brackets are registered first (--align, --no-align).\n"
      "Example: rsibr hdr shoot/photoset.yaml --out shoot/hdr --json shoot/hdr.json");
  c->add_option("photoset", a->photoset, "photoset.yaml or the folder holding it")->required();
  c->add_option("--out", a->out, "Output folder (created if missing; its parent must exist)")->required();
  c->add_option("--view", a->views, "Merge only this view (repeatable; default: all)");
  c->add_option("--response", a->response, "Reuse this response curve file (from an earlier run, same camera)");
  c->add_option("--model", a->model,
                "Response model: auto (held-out error), identity, gamma, polynomial, robertson, debevec");
  c->add_option("--channels", a->channels,
                "Response curves: auto (held-out error), shared (one curve for R, G, B: in-camera JPEG), separate");
  c->add_option("--samples", a->samples, "Pixels sampled for response recovery, over all views")
      ->check(CLI::Range(100, 200000));
  c->add_option("--smoothness", a->smoothness, "Smoothness weight lambda of the debevec and robertson curves")
      ->check(CLI::Range(0.0, 1e8));
  c->add_option("--saturation-code", a->saturation,
                "Codes at or above this saturate: N or R,G,B (default: measured from the brackets)");
  c->add_option("--white-balance", a->white_balance,
                "camera (default: keep the camera's own) or R,G,B gains applied to the merged radiance");
  c->add_option("--noise", a->noise, "Given noise model SHOT,READ: var(X) = SHOT*X + READ, X normalised to saturation");
  auto* on = c->add_flag("--align", a->align,
                         "Apply every shift the median threshold bitmaps find (default: only shifts that make the "
                         "brackets agree better; files of different sizes are registered on the middle one)");
  c->add_flag("--no-align", a->no_align, "Never shift brackets; files of different sizes are an error")->excludes(on);
  c->add_flag("--deghost", a->deghost, "Ghost pixels take the longest usable bracket alone instead of a blend");
  c->add_option("--ghost-sigmas", a->ghost_sigmas,
                "Ghost threshold in standard deviations of chi-square (default: 6, 8 for JPEG)")
      ->check(CLI::Range(0.0, 1e6));
  c->add_option("--vignetting", a->vignetting,
                "Lens falloff divided out: auto (from the photo set's chessboards, else lensfun's profile of the "
                "lens the EXIF names, else none), none, or a vignetting.json (as rsibr process does)");
  c->add_option("--lens", a->lens,
                "The camera's .cameramodel: the principal point vignetting is about (default: the photo set's "
                "camera model, else the image centre)");
  c->add_option("--input-colorspace", a->input_colour_space,
                "OpenColorIO colour space of the linearised camera RGB (default: the working space; $OCIO honoured)");
  c->add_option("--preview-exposure", a->preview_exposure, "Preview exposure in stops (default: median grey at 0.18)");
  c->add_flag("--no-preview", a->no_preview, "Do not write PNG previews");
  c->add_option("--json", a->json, "Write a JSON summary to FILE ('-' for stdout)");
  c->add_flag("-q,--quiet", a->quiet, "No progress bar or report lines");
  return [a] { return run_hdr(*a); };
}

}  // namespace rsibr::cli
