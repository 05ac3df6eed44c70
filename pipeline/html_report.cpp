#include "pipeline/html_report.h"

#include "formats/atomic_file.h"
#include "core/colour.h"
#include "compare/compare_pictures.h"
#include "formats/exr_io.h"
#include "core/preview_exposure.h"
#include "core/sphere_mesh.h"
#include "core/text.h"
#include "formats/map_set.h"
#include "runtime/web_viewer_page.h"
#include "pipeline/light_sources_report.h"
#include "pipeline/process_pipeline.h"
#include "pipeline/response_choice_html.h"
#include "pipeline/step_record.h"
#include "formats/image_codecs.h"

#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <iterator>
#include <sstream>
#include <stdexcept>

namespace rsibr {

namespace fs = std::filesystem;

std::string html_escape(const std::string& text) {
  std::string out;
  for (char ch : valid_utf8(text)) {
    switch (ch) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&#39;"; break;
      default: out += ch;
    }
  }
  return out;
}

namespace {

std::string num(double v, int precision = 4) {
  if (!std::isfinite(v)) return "-";
  std::ostringstream s;
  s << std::setprecision(precision) << v;
  return s.str();
}

std::string jnum(const nlohmann::json& j, int precision = 4) {
  return j.is_number() ? num(j.get<double>(), precision)
                       : html_escape(j.is_string() ? j.get<std::string>()
                                                   : j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace));
}

std::string img_tag(const std::vector<unsigned char>& png, const std::string& alt, const std::string& style = "") {
  return "<img alt=\"" + html_escape(alt) + "\"" + (style.empty() ? "" : " style=\"" + style + "\"") +
         " src=\"data:image/png;base64," + base64_encode(png) + "\">";
}

// A picture a step record lists, embedded only when it lies inside the run folder `dir` (symlinks
// resolved): a record copied from elsewhere must not make the report carry files from outside it.
std::vector<unsigned char> read_bytes(const fs::path& dir, const fs::path& file) {
  std::error_code ec1, ec2;
  const fs::path root = fs::weakly_canonical(fs::absolute(dir), ec1),
                 real = fs::weakly_canonical(fs::absolute(file), ec2);
  const fs::path rel = real.lexically_relative(root);
  if (ec1 || ec2 || rel.empty() || *rel.begin() == "..")
    throw std::runtime_error(file.string() + ": listed in a step record but outside the run folder " + dir.string());
  std::ifstream in(file, std::ios::binary);
  if (!in) throw std::runtime_error(file.string() + ": cannot read (listed in a step record)");
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// The ball's captured and computed map sets on a sphere, one camera, a wipe between them
// (runtime/web_viewer_page.h) in a frame; a note where the views hold no spherical triangle (fewer
// than three, or all on one great circle), which the shader's point location needs.
std::string captured_computed_viewer(const fs::path& dir, const std::string& ball) {
  const fs::path captured = dir / "maps" / ("captured-" + ball + ".exr"),
                 computed = dir / "maps" / ("computed-" + ball + ".exr");
  if (!fs::exists(captured) || !fs::exists(computed)) return "";
  try {
    const MapSet a = read_map_set(captured.string()), b = read_map_set(computed.string());
    const Mesh sphere = sphere_mesh(Eigen::Vector3f::Zero(), 1.f);
    WebViewerPage page;
    page.maps = &a;
    page.maps2 = &b;
    page.names[0] = "captured";
    page.names[1] = "computed";
    page.mesh = &sphere;
    // From the first view's side (where the shoot saw the ball), exposed like the probe's pictures.
    page.camera = frame_bounds(sphere.bounds(), -a.views.front().view, Vec3(0, 1, 0), 30, 320, 240);
    std::vector<cv::Mat> rgb;
    for (const MapView& v : a.views) rgb.push_back(v.rgb);
    page.exposure = preview_exposure(rgb);
    page.title = ball + ": captured | computed";
    const std::string html = web_viewer_page(page);
    return "<p>The two on one sphere, one camera: drag to orbit, the wipe slider to compare.</p><iframe "
           "class=\"viewer\" title=\"" +
           html_escape(ball) + " captured and computed\" style=\"border:0;width:100%;height:400px\" srcdoc=\"" +
           html_escape(html) + "\"></iframe>";
  } catch (const std::exception& e) {  // the report never fails for a live view it cannot make
    return "<p>(No live view of the two: " + html_escape(e.what()) + ".)</p>";
  }
}

// Hdr: the vignetting model divided out of the merge (hdr/vignetting.h).
void write_vignetting_section(std::ostringstream& h, const nlohmann::json& v) {
  const nlohmann::json& m = v.value("model", nlohmann::json::object());
  h << "<h3>Vignetting</h3><p>";
  if (m.contains("k") && m.value("source", "none") != "none") {
    h << "Divided out of every view: v = 1 + k1 r&sup2; + k2 r&#8308; + k3 r&#8310; (r = 1 at the farthest corner), k = ("
      << jnum(m["k"][0]) << ", " << jnum(m["k"][1]) << ", " << jnum(m["k"][2]) << "), the corner "
      << jnum(m["corner_stops"], 3) << " stops darker; " << html_escape(m.value("source", "")) << ".";
    if (v.contains("estimate") && v["estimate"].contains("lensfun_lens")) {
      const auto& e = v["estimate"];
      h << " From the lensfun database's profile of " << html_escape(e["lensfun_lens"].get<std::string>())
        << " at the photos' focal length and aperture (fitted to lensfun's correction to "
        << num(100 * e["fit_rms"].get<double>(), 2) << "% RMS); no chessboards to measure it.";
    } else if (v.contains("estimate")) {
      const auto& e = v["estimate"];
      h << " Estimated from " << jnum(e["squares"]) << " white squares on " << jnum(e["boards"]) << " boards ("
        << jnum(e["degree"]) << " term(s) chosen by leave-one-board-out error), fit RMS "
        << num(100 * e["rms"].get<double>(), 2) << "%, corner &sigma; " << jnum(e["corner_sigma_stops"], 2)
        << " stops; squares reach r = " << jnum(e["max_r"], 2) << " (beyond, the polynomial extrapolates).";
    }
  } else {
    h << "Not corrected";
  }
  if (v.contains("note")) h << " " << html_escape(v["note"].get<std::string>());
  h << "</p>";
}

// Orient: the world's up and the views left out.
void write_orientation_notes(std::ostringstream& h, const nlohmann::json& s) {
  if (s.contains("world_up") && s["world_up"].is_object()) {
    const auto& w = s["world_up"];
    h << "<p>World up estimated from the views (cameras held level in roll): "
      << jnum(w["tilt_from_first_camera_deg"], 3) << " degrees from the first camera's up, &sigma; "
      << jnum(w["sigma_deg"], 2) << " degrees (roll scatter " << jnum(w["roll_sigma_deg"], 2) << " degrees, "
      << (w.value("roll_sigma_estimated", false) ? "from the views" : "assumed") << ").</p>";
  }
  if (s.contains("notes") && !s["notes"].empty()) {
    h << "<p><b>Chrome balls found across views:</b>";
    for (const auto& l : s["notes"]) h << "<br>" << html_escape(l.get<std::string>());
    h << "</p>";
  }
  if (s.contains("left_out") && !s["left_out"].empty()) {
    h << "<p class=\"warn\"><b>Views left out:</b>";
    for (const auto& l : s["left_out"]) h << "<br>" << html_escape(l.get<std::string>());
    h << "</p>";
  }
}

// Orient: per pair of views, what tied them (the rotation search, the matches, the inliers against
// chance, how the views agree) and the picture of the matches.
void write_orientation_pairs(std::ostringstream& h, const nlohmann::json& s, const fs::path& dir) {
  if (!s.contains("solve") || !s["solve"].is_object() || !s["solve"].contains("pairs")) return;
  const nlohmann::json& solve = s["solve"];
  if (solve["pairs"].empty()) return;
  h << "<h3>Pairs of views</h3><p>Inliers: shared tracks whose directions agree within 2 degrees at the solved "
       "rotations (in brackets, what chance gives when the matching was gated by the rotation search). Offset "
       "and mismatch: the median log2 ratio of the two views' luminance where both see a direction, and the "
       "median deviation around it (stops).</p><table><tr><th>views</th><th>search score (runner-up)</th>"
       "<th>matches</th><th>inliers</th><th>offset</th><th>mismatch</th></tr>";
  for (const auto& p : solve["pairs"]) {
    h << "<tr><td>" << html_escape(p["views"][0].get<std::string>() + " - " + p["views"][1].get<std::string>())
      << "</td><td>";
    if (p.contains("search")) h << jnum(p["search"]["score"], 3) << " (" << jnum(p["search"]["runner_up"], 3) << ")";
    h << "</td><td>" << jnum(p["matched"]) << "</td><td>" << jnum(p["inliers"]);
    if (p.value("matched_under_search", false)) h << " (" << jnum(p["inliers_by_chance"], 3) << ")";
    h << "</td><td>";
    if (p.contains("agreement")) h << jnum(p["agreement"]["median_log2_ratio"], 3);
    h << "</td><td>";
    if (p.contains("agreement")) h << jnum(p["agreement"]["mismatch_stops"], 3);
    h << "</td></tr>";
  }
  h << "</table>";
  for (const auto& f : solve.value("pair_pictures", nlohmann::json::array()))
    h << "<p>" << html_escape(f.get<std::string>()) << " (green: tracks the solve took; red: the others)<br>"
      << img_tag(read_bytes(dir, dir / f.get<std::string>()), f.get<std::string>(), "max-width:100%") << "</p>";
}

// Extract: every ball of every view as identified, and each chrome view's mask.
void write_balls_section(std::ostringstream& h, const nlohmann::json& s, const fs::path& dir) {
  h << "<h2>Balls</h2><p>Each listed ball of each view, identified by its outline, its appearance and the rig's "
       "geometry across views; a ball not found with confidence is left out of its maps.</p>"
       "<table><tr><th>view</th><th>ball</th><th>status</th><th>centre (px)</th><th>radius (px)</th>"
       "<th>outline RMS (px)</th><th>confident</th><th>note</th></tr>";
  for (const auto& v : s["views"]) {
    const std::string name = v["name"].get<std::string>();
    if (v.contains("left_out")) {
      h << "<tr><td>" << html_escape(name) << "</td><td>-</td><td>left out</td><td></td><td></td><td></td><td></td><td>"
        << html_escape(v["left_out"].get<std::string>()) << "</td></tr>";
      continue;
    }
    for (const auto& b : v["balls"]) {
      const bool found = b.contains("centre_px");
      h << "<tr><td>" << html_escape(name) << "</td><td>" << html_escape(b["ball"].get<std::string>()) << "</td><td"
        << (found ? "" : " class=\"warn\"") << ">" << html_escape(b.value("status", ""))
        << (b.value("cut", false) ? ", cut by the frame" : "") << "</td>";
      if (found)
        h << "<td>(" << jnum(b["centre_px"][0], 5) << ", " << jnum(b["centre_px"][1], 5) << ")</td><td>"
          << jnum(b["radius_px"]) << "</td><td>" << jnum(b["outline_rms_px"]) << "</td><td>"
          << (b.contains("confident_fraction") ? num(100 * b["confident_fraction"].get<double>(), 3) + "%" : "")
          << "</td>";
      else
        h << "<td></td><td></td><td></td><td></td>";
      h << "<td style=\"text-align:left\">" << html_escape(b.value("note", "")) << "</td></tr>";
    }
  }
  h << "</table>";
  bool any = false;
  for (const auto& v : s["views"])
    for (const auto& b : v["balls"])
      if (b.contains("mask")) {
        if (!any)
          h << "<h3>Masks</h3><p>Each view's map of each ball (left) and its confidence (right): red is left out "
               "(chrome: the camera and photographer, the stands, the other balls; grey: what this view alone sees "
               "differently, a shadow of the photographer; both: a ball in front, clipped pixels, the rim).</p>";
        any = true;
        h << "<p>" << html_escape(v["name"].get<std::string>() + " " + b["ball"].get<std::string>()) << "<br>"
          << img_tag(read_bytes(dir, dir / b["mask"].get<std::string>()), v["name"].get<std::string>()) << "</p>";
      }
}

}  // namespace

std::string svg_line_plot(const std::vector<PlotSeries>& series, const std::string& x_label, const std::string& y_label,
                          int width, int height) {
  double x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY;
  for (const PlotSeries& s : series)
    for (std::size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
      x0 = std::min(x0, s.x[i]), x1 = std::max(x1, s.x[i]), y0 = std::min(y0, s.y[i]), y1 = std::max(y1, s.y[i]);
    }
  if (!(x1 > x0)) x0 = 0, x1 = 1;
  if (!(y1 > y0)) y1 = y0 + 1;
  if (!std::isfinite(y0)) y0 = 0, y1 = 1;
  const double l = 60, r = 16, t = 12, b = 40, w = width - l - r, h = height - t - b;
  auto px = [&](double x) { return l + (x - x0) / (x1 - x0) * w; };
  auto py = [&](double y) { return t + h - (y - y0) / (y1 - y0) * h; };
  std::ostringstream s;
  s << std::setprecision(5);
  s << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << width << "\" height=\"" << height
    << "\" font-family=\"sans-serif\" font-size=\"11\">";
  s << "<rect x=\"" << l << "\" y=\"" << t << "\" width=\"" << w << "\" height=\"" << h
    << "\" fill=\"#fafafa\" stroke=\"#888\"/>";
  s << "<text x=\"" << l << "\" y=\"" << t + h + 14 << "\">" << num(x0) << "</text>";
  s << "<text x=\"" << l + w << "\" y=\"" << t + h + 14 << "\" text-anchor=\"end\">" << num(x1) << "</text>";
  s << "<text x=\"" << l - 4 << "\" y=\"" << t + h << "\" text-anchor=\"end\">" << num(y0) << "</text>";
  s << "<text x=\"" << l - 4 << "\" y=\"" << t + 10 << "\" text-anchor=\"end\">" << num(y1) << "</text>";
  s << "<text x=\"" << l + w / 2 << "\" y=\"" << height - 6 << "\" text-anchor=\"middle\">" << html_escape(x_label)
    << "</text>";
  s << "<text transform=\"translate(14," << t + h / 2 << ") rotate(-90)\" text-anchor=\"middle\">"
    << html_escape(y_label) << "</text>";
  int legend = 0;
  for (const PlotSeries& se : series) {
    s << "<polyline fill=\"none\" stroke=\"" << html_escape(se.colour) << "\" stroke-width=\"1.5\" points=\"";
    for (std::size_t i = 0; i < se.x.size() && i < se.y.size(); ++i)
      if (std::isfinite(se.x[i]) && std::isfinite(se.y[i])) s << px(se.x[i]) << "," << py(se.y[i]) << " ";
    s << "\"/>";
    s << "<text x=\"" << l + 8 << "\" y=\"" << t + 16 + 14 * legend++ << "\" fill=\"" << html_escape(se.colour) << "\">"
      << html_escape(se.name) << "</text>";
  }
  s << "</svg>";
  return s.str();
}

// The step that stopped the run (DIR/steps/STEP.failed.json): its error, what it had found, and
// the pictures a user needs to help it (the pairs' matches, the ball candidates).
void write_failed_step_section(std::ostringstream& h, const std::string& step, const nlohmann::json& failed,
                               const fs::path& dir) {
  h << "<h2>Stopped at " << html_escape(step) << "</h2><p class=\"warn\">"
    << html_escape(failed.value("error", std::string("(no message)"))) << "</p>";
  const nlohmann::json summary = failed.value("summary", nlohmann::json::object());
  if (step == "orient" && summary.is_object()) {
    write_orientation_notes(h, summary);
    write_orientation_pairs(h, summary, dir);
  }
  if (step == "balls" || step == "lens" || step == "orient" || step == "extract") {
    std::vector<fs::path> pictures;
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(dir / "balls", ec))
      if (e.path().extension() == ".png") pictures.push_back(e.path());
    std::sort(pictures.begin(), pictures.end());
    if (!pictures.empty())
      h << "<h3>Ball candidates</h3><p>Each view's candidates, numbered; give the right one with "
           "<code>--ball VIEW:BALL=X,Y,R</code>.</p>";
    for (const fs::path& f : pictures)
      h << "<p>" << html_escape(f.filename().string()) << "<br>"
        << img_tag(read_bytes(dir, f), f.filename().string(), "max-width:100%") << "</p>";
  }
}

void write_process_report(const fs::path& dir, const fs::path& out, const std::string& photoset) {
  std::map<std::string, StepRecord> rec;
  std::map<std::string, nlohmann::json> failed;  // steps that stopped, with no record of their own
  for (const std::string& step : process_steps()) {
    if (step == "report") continue;
    if (fs::exists(step_record_path(dir, step))) {
      rec[step] = read_step_record(dir, step);
    } else if (fs::exists(failed_step_record_path(dir, step))) {
      try {
        std::ifstream in(failed_step_record_path(dir, step));
        failed[step] = nlohmann::json::parse(in);
      } catch (const std::exception&) {
        failed[step] = {{"error", "its record of the failure cannot be read"}};
      }
    }
  }
  std::ostringstream h;
  h << "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>rsibr process report</title><style>"
       "body{font-family:sans-serif;max-width:1100px;margin:1em auto;padding:0 1em;color:#222}"
       "table{border-collapse:collapse;margin:.5em 0}td,th{border:1px solid #ccc;padding:2px 8px;text-align:right}"
       "th{background:#eee}td:first-child,th:first-child{text-align:left}img{max-width:100%;image-rendering:pixelated}"
       ".frames img{width:24%;margin:.2%}h2{border-bottom:1px solid #ccc}.warn{background:#fff3cd;padding:4px}</style></head><body>\n";
  h << "<h1>rsibr process report</h1><p>Photo set: <code>" << html_escape(photoset) << "</code><br>Output: <code>"
    << html_escape(dir.string()) << "</code><br>rsibr " << RSIBR_VERSION << "</p>\n";

  // Timings.
  h << "<h2>Steps</h2><table><tr><th>step</th><th>seconds</th></tr>";
  double total = 0;
  for (const std::string& step : process_steps()) {
    if (step == "report") continue;
    if (rec.count(step)) {
      total += rec[step].seconds;
      h << "<tr><td>" << step << "</td><td>" << num(rec[step].seconds, 3) << "</td></tr>";
    } else {
      h << "<tr><td>" << step << "</td><td>" << (failed.count(step) ? "<b>failed</b>" : "not run") << "</td></tr>";
    }
  }
  h << "<tr><th>total</th><th>" << num(total, 3) << "</th></tr></table>\n";
  for (const auto& [step, f] : failed) write_failed_step_section(h, step, f, dir);

  if (rec.count("calibrate")) {
    const auto& s = rec["calibrate"].summary;
    h << "<h2>Lens</h2><p>Model <b>" << html_escape(s.value("model", "")) << "</b> ("
      << html_escape(s.value("source", "")) << ")";
    if (s.contains("rms_px"))
      h << ", reprojection RMS " << jnum(s["rms_px"]) << " px over " << jnum(s["boards_found"]) << " boards";
    if (s.value("source", "") == "exif" || s.value("source", "") == "lensfun")
      h << ": no chessboards and no camera model, so the photos' metadata (" << html_escape(s.value("focal_from", ""))
        << ") gives f = " << num(s.value("focal_px", 0.0), 4) << " px &plusmn; "
        << num(100 * s.value("focal_sigma_relative", 0.0), 2) << "% (1 sigma), " << html_escape(s.value("assumed", ""))
        << "; chessboards or --lens give a measured lens";
    if (s.value("source", "") == "outlines")
      h << ": no chessboards, no camera model and no focal length in the photos' metadata, so "
        << html_escape(s.value("assumed", ""));
    if (s.contains("lensfun") && s["lensfun"].is_string())
      h << " (no distortion profile: " << html_escape(s["lensfun"].get<std::string>()) << ")";
    h << ".</p>";
    if (s.contains("models")) {
      h << "<table><tr><th>model</th><th>held-out RMS (px)</th><th>fit RMS (px)</th></tr>";
      for (const auto& m : s["models"])
        h << "<tr><td>" << html_escape(m["model"].get<std::string>()) << "</td><td>" << jnum(m["held_out_rms_px"])
          << "</td><td>" << jnum(m["fit_rms_px"]) << "</td></tr>";
      h << "</table>";
    }
  }
  if (rec.count("lens")) {
    // The lens step (pipeline/lens_step.h): a metadata lens's focal length from the balls' outlines.
    const auto& s = rec["lens"].summary;
    if (s.value("far_camera", false)) {
      h << "<p><b>Crops of the ball: the far-camera model.</b> Every view's ball fills its frame, so the photos "
        << "are crops and their metadata's focal length belongs to the uncropped frame: the lens is a distant, "
        << "near-orthographic pinhole (f = " << num(s.value("focal_px", 0.0), 4) << " px on a " << jnum(s["canvas"][0])
        << "x" << jnum(s["canvas"][1]) << " canvas; the ball's half-angle "
        << num(s.value("ball_half_angle_deg", 0.0), 2) << " degrees). The perspective a crop cannot tell (about "
        << "the ball's radius over its distance, across the ball) is left out.</p>";
    } else if (s.value("refined", false) && s.value("source", "") == "outlines") {
      h << "<p>Focal length measured from " << jnum(s["balls_used"]) << " ball outline(s) (" << jnum(s["points"])
        << " points, RMS " << num(s.value("outline_rms_px", 0.0), 3) << " px): f = <b>"
        << num(s.value("focal_px", 0.0), 5) << " &plusmn; " << num(s.value("sigma_px", 0.0), 3) << " px</b>.";
      if (!s.value("note", "").empty()) h << " " << html_escape(s.value("note", "")) << ".";
      h << "</p>";
    } else if (s.value("refined", false)) {
      h << "<p>Focal length refined from " << jnum(s["balls_used"]) << " ball outline(s) (" << jnum(s["points"])
        << " points, RMS " << num(s.value("outline_rms_px", 0.0), 3) << " px): the outlines alone say "
        << num(s.value("outline_focal_px", 0.0), 5) << " &plusmn; " << num(s.value("outline_sigma_px", 0.0), 3)
        << " px, the metadata " << num(s.value("prior_focal_px", 0.0), 5) << " &plusmn; "
        << num(s.value("prior_sigma_px", 0.0), 3) << " px; combined f = <b>" << num(s.value("focal_px", 0.0), 5)
        << " &plusmn; " << num(s.value("sigma_px", 0.0), 3) << " px</b> ("
        << num(100 * s.value("change_relative", 0.0), 3) << "% from the metadata's).";
      if (!s.value("note", "").empty()) h << " " << html_escape(s.value("note", "")) << ".";
      h << "</p>";
    } else if (s.value("source", "") == "exif" || s.value("source", "") == "lensfun") {
      h << "<p>The focal length was not refined from the balls' outlines: " << html_escape(s.value("why", ""))
        << ".</p>";
    }
  }

  if (rec.count("hdr")) {
    const auto& s = rec["hdr"].summary;
    h << "<h2>Camera response</h2><p>";
    if (!s.value("camera", "").empty()) h << "Camera <b>" << html_escape(s.value("camera", "")) << "</b>. ";
    h << "Model <b>" << html_escape(s.value("model", "")) << "</b>, recovered from "
      << html_escape(s.value("recovered_from", "")) << ".</p>";
    h << response_choice_html(s.value("recovery", nlohmann::json::object()));
    std::vector<PlotSeries> series = {{"R", "#d33", {}, {}}, {"G", "#2a2", {}, {}}, {"B", "#33d", {}, {}}};
    for (const auto& p : s["curve"])
      for (int ch = 0; ch < 3; ++ch)
        series[ch].x.push_back(p[0].get<double>()), series[ch].y.push_back(p[ch + 1].get<double>());
    h << svg_line_plot(series, "pixel code", "relative exposure X (linear)");
    h << "<table><tr><th>view</th><th>brackets</th><th>clipped</th><th>ghost</th></tr>";
    for (const auto& v : s["views"])
      h << "<tr><td>" << html_escape(v["name"].get<std::string>()) << "</td><td>" << jnum(v["brackets"]) << "</td><td>"
        << num(100 * v["clipped_fraction"].get<double>(), 3) << "%</td><td>"
        << num(100 * v["ghost_fraction"].get<double>(), 3) << "%</td></tr>";
    h << "</table>";
    if (s.contains("vignetting")) write_vignetting_section(h, s["vignetting"]);
  }

  if (rec.count("orient")) {
    const auto& s = rec["orient"].summary;
    h << "<h2>Orientations</h2><p>Source: " << html_escape(s.value("source", "")) << ", gauge "
      << html_escape(s.value("gauge", ""))
      << ".</p><table><tr><th>view</th><th>forward (world)</th><th>&sigma; (deg)</th></tr>";
    for (const auto& v : s["views"])
      h << "<tr><td>" << html_escape(v["name"].get<std::string>()) << "</td><td>(" << jnum(v["forward"][0], 3) << ", "
        << jnum(v["forward"][1], 3) << ", " << jnum(v["forward"][2], 3) << ")</td><td>" << jnum(v["sigma_deg"])
        << "</td></tr>";
    h << "</table>";
    write_orientation_notes(h, s);
    write_orientation_pairs(h, s, dir);
  }

  if (rec.count("extract")) write_balls_section(h, rec["extract"].summary, dir);

  if (rec.count("probe")) {
    const auto& s = rec["probe"].summary;
    const EnvMap probe = read_environment((dir / "probe.exr").string());
    const float stops = preview_exposure(probe.pixels);
    std::vector<unsigned char> png;
    encode_image(".png", display_encode(probe.pixels, stops), png);
    h << "<h2>Light probe</h2><p>" << jnum(s["views"]) << " chrome views blended, "
      << num(100 * s["covered_fraction"].get<double>(), 3) << "% of the sphere seen";
    if (s.contains("well_seen_fraction"))
      h << ", " << num(100 * s["well_seen_fraction"].get<double>(), 3) << "% seen well (summed confidence at least 1/2"
        << (s.value("views", 0) == 1 ? "; one view: behind the ball only its stretched rim, low confidence" : "")
        << ")";
    if (rec.count("sources")) {
      const auto& src = rec["sources"].summary;
      if (src.value("filled_fraction", 0.0) > 0)
        h << "; " << num(100 * src["filled_fraction"].get<double>(), 3)
          << "% no view saw, filled from the surroundings (no measurement there: the probe's confidence is 0)";
      if (src.contains("lower_bound_fraction") && !src.value("regions", nlohmann::json::array()).empty()) {
        const auto& f = src["lower_bound_fraction"];
        double largest = 0;
        for (const auto& v : f) largest = std::max(largest, v.get<double>());
        if (largest > 0)
          h << "; " << num(100 * f[0].get<double>(), 3) << "% / " << num(100 * f[1].get<double>(), 3) << "% / "
            << num(100 * f[2].get<double>(), 3) << "% (R / G / B) of its light is only a lower bound (clipped in every "
            << "bracket, nothing recovered it)";
      }
    }
    h << " (lat-long, tone-mapped";
    const bool sources =
        rec.count("sources") && !rec["sources"].summary.value("sources", nlohmann::json::array()).empty();
    if (sources && fs::is_regular_file(dir / "probe-measured.exr")) {
      // Before (as measured) and after (with the recovered sources), at the final probe's exposure.
      const EnvMap measured = read_environment((dir / "probe-measured.exr").string());
      std::vector<unsigned char> before;
      encode_image(".png", display_encode(measured.pixels, stops), before);
      h << "; as measured, then with the recovered sources).</p>" << img_tag(before, "probe as measured")
        << img_tag(png, "probe");
    } else {
      h << ").</p>" << img_tag(png, "probe");
    }
  }
  if (rec.count("sources")) h << light_sources_section(dir, rec["sources"].summary);

  if (rec.count("compare")) {
    const auto& s = rec["compare"].summary;
    h << "<h2>Captured vs computed</h2><p>Captured grey-ball maps against maps baked from the probe (Lambert). "
         "Errors after the global exposure / white-balance fit are errors of shape; the fitted gains are the "
         "calibration offset. Heat maps: log2 error (stops).</p>";
    // Light clipped in every chrome view (a sun): what the sources step recovered, or how much is
    // missing; nothing when nothing was clipped.
    if (rec.count("sources")) h << light_sources_warning(rec["sources"].summary);
    for (const auto& b : s["balls"]) {
      h << "<h3>" << html_escape(b["ball"].get<std::string>()) << "</h3>";
      if (b.contains("untrusted_views") && !b["untrusted_views"].empty()) {
        h << "<p class=\"warn\">Left out (the ball has no trusted texel there: hidden behind another ball, or not found):";
        for (const auto& v : b["untrusted_views"]) h << " " << html_escape(v.get<std::string>());
        h << ".</p>";
      }
      if (!b.contains("overall")) continue;
      if (b.contains("fit"))
        h << "<p>Fitted gains R, G, B: " << jnum(b["fit"]["gains"][0]) << ", " << jnum(b["fit"]["gains"][1]) << ", "
          << jnum(b["fit"]["gains"][2]) << " (" << jnum(b["fit"]["exposure_stops"], 3) << " stops).</p>";
      h << "<table><tr><th>view</th><th>rel RMS before</th><th>rel RMS after</th><th>log RMS after (stops)</th>"
           "<th>PSNR after (dB)</th></tr>";
      for (const auto& v : b["views"])
        h << "<tr><td>" << html_escape(v["image"].get<std::string>()) << "</td><td>"
          << jnum(v["before"]["relative_rms"]) << "</td><td>" << jnum(v["after"]["relative_rms"]) << "</td><td>"
          << jnum(v["after"]["log_rms_stops"]) << "</td><td>" << jnum(v["after"]["psnr_db"]) << "</td></tr>";
      h << "<tr><th>overall</th><th>" << jnum(b["overall"]["before"]["relative_rms"]) << "</th><th>"
        << jnum(b["overall"]["after"]["relative_rms"]) << "</th><th>" << jnum(b["overall"]["after"]["log_rms_stops"])
        << "</th><th>" << jnum(b["overall"]["after"]["psnr_db"]) << "</th></tr></table>";
      for (const auto& v : b["views"])
        h << "<p>"
          << img_tag(read_bytes(dir, dir / fs::path(b["folder"].get<std::string>()) / v["picture"].get<std::string>()),
                     v["image"].get<std::string>())
          << "</p>";
      h << captured_computed_viewer(dir, b["ball"].get<std::string>());
    }
  }

  if (rec.count("render")) {
    const auto& s = rec["render"].summary;
    h << "<h2>Turntable</h2><p>" << html_escape(s.value("mesh", "")) << " (" << jnum(s["triangles"]) << " triangles), "
      << html_escape(s.value("material", "")) << ", rendered by the runtime from maps baked from the probe; "
      << jnum(s["seconds_per_frame"], 3) << " s per frame.</p><div class=\"frames\">";
    for (const fs::path& f : rec["render"].outputs)
      if (f.extension() == ".png") h << img_tag(read_bytes(dir, f), f.filename().string());
    h << "</div>";
    // The turntable to orbit (WebGL2; the page says why where it cannot draw), in its own frame.
    for (const fs::path& f : rec["render"].outputs)
      if (f.filename() == "viewer.html") {
        const std::vector<unsigned char> page = read_bytes(dir, f);
        h << "<p>Drag to orbit, wheel to zoom (the same maps, drawn per pixel by WebGL2 in this page):</p>"
          << "<iframe class=\"viewer\" title=\"turntable viewer\" style=\"border:0;width:100%;height:"
          << (s.contains("size") ? s["size"][1].get<int>() : 240) + 160 << "px\" srcdoc=\""
          << html_escape(std::string(page.begin(), page.end())) << "\"></iframe>";
      }
  }
  h << "</body></html>\n";
  write_text_atomically(out, h.str());
}

}  // namespace rsibr
