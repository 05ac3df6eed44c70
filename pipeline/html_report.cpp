#include "pipeline/html_report.h"

#include "core/atomic_file.h"
#include "core/colour.h"
#include "core/compare_pictures.h"
#include "core/exr_io.h"
#include "pipeline/process_pipeline.h"
#include "pipeline/response_choice_html.h"
#include "pipeline/step_record.h"

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
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

std::string base64_encode(const std::vector<unsigned char>& in) {
  static const char* table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((in.size() + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 2 < in.size(); i += 3) {
    const unsigned v = (in[i] << 16) | (in[i + 1] << 8) | in[i + 2];
    out += table[(v >> 18) & 63], out += table[(v >> 12) & 63], out += table[(v >> 6) & 63], out += table[v & 63];
  }
  if (i + 1 == in.size()) {
    const unsigned v = in[i] << 16;
    out += table[(v >> 18) & 63], out += table[(v >> 12) & 63], out += "==";
  } else if (i + 2 == in.size()) {
    const unsigned v = (in[i] << 16) | (in[i + 1] << 8);
    out += table[(v >> 18) & 63], out += table[(v >> 12) & 63], out += table[(v >> 6) & 63], out += '=';
  }
  return out;
}

std::string html_escape(const std::string& text) {
  std::string out;
  for (char ch : text) {
    switch (ch) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
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
  return j.is_number() ? num(j.get<double>(), precision) : html_escape(j.is_string() ? j.get<std::string>() : j.dump());
}

std::string img_tag(const std::vector<unsigned char>& png, const std::string& alt, const std::string& style = "") {
  return "<img alt=\"" + html_escape(alt) + "\"" + (style.empty() ? "" : " style=\"" + style + "\"") +
         " src=\"data:image/png;base64," + base64_encode(png) + "\">";
}

std::vector<unsigned char> read_bytes(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw std::runtime_error(file.string() + ": cannot read (listed in a step record)");
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
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
    s << "<text x=\"" << l + 8 << "\" y=\"" << t + 16 + 14 * legend++ << "\" fill=\"" << html_escape(se.colour)
      << "\">" << html_escape(se.name) << "</text>";
  }
  s << "</svg>";
  return s.str();
}

void write_process_report(const fs::path& dir, const fs::path& out, const std::string& photoset) {
  std::map<std::string, StepRecord> rec;
  for (const std::string& step : process_steps())
    if (step != "report" && fs::exists(step_record_path(dir, step))) rec[step] = read_step_record(dir, step);
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
      h << "<tr><td>" << step << "</td><td>not run</td></tr>";
    }
  }
  h << "<tr><th>total</th><th>" << num(total, 3) << "</th></tr></table>\n";

  if (rec.count("calibrate")) {
    const auto& s = rec["calibrate"].summary;
    h << "<h2>Lens</h2><p>Model <b>" << html_escape(s.value("model", "")) << "</b> (" << html_escape(s.value("source", ""))
      << ")";
    if (s.contains("rms_px")) h << ", reprojection RMS " << jnum(s["rms_px"]) << " px over " << jnum(s["boards_found"]) << " boards";
    h << ".</p>";
    if (s.contains("models")) {
      h << "<table><tr><th>model</th><th>held-out RMS (px)</th><th>fit RMS (px)</th></tr>";
      for (const auto& m : s["models"])
        h << "<tr><td>" << html_escape(m["model"].get<std::string>()) << "</td><td>" << jnum(m["held_out_rms_px"])
          << "</td><td>" << jnum(m["fit_rms_px"]) << "</td></tr>";
      h << "</table>";
    }
  }

  if (rec.count("hdr")) {
    const auto& s = rec["hdr"].summary;
    h << "<h2>Camera response</h2><p>Model <b>" << html_escape(s.value("model", "")) << "</b>, recovered from "
      << html_escape(s.value("recovered_from", "")) << ".</p>";
    h << response_choice_html(s.value("recovery", nlohmann::json::object()));
    std::vector<PlotSeries> series = {{"R", "#d33", {}, {}}, {"G", "#2a2", {}, {}}, {"B", "#33d", {}, {}}};
    for (const auto& p : s["curve"])
      for (int ch = 0; ch < 3; ++ch) series[ch].x.push_back(p[0].get<double>()), series[ch].y.push_back(p[ch + 1].get<double>());
    h << svg_line_plot(series, "pixel code", "relative exposure X (linear)");
    h << "<table><tr><th>view</th><th>brackets</th><th>clipped</th><th>ghost</th></tr>";
    for (const auto& v : s["views"])
      h << "<tr><td>" << html_escape(v["name"].get<std::string>()) << "</td><td>" << jnum(v["brackets"]) << "</td><td>"
        << num(100 * v["clipped_fraction"].get<double>(), 3) << "%</td><td>"
        << num(100 * v["ghost_fraction"].get<double>(), 3) << "%</td></tr>";
    h << "</table>";
  }

  if (rec.count("orient")) {
    const auto& s = rec["orient"].summary;
    h << "<h2>Orientations</h2><p>Source: " << html_escape(s.value("source", "")) << ", gauge "
      << html_escape(s.value("gauge", "")) << ".</p><table><tr><th>view</th><th>forward (world)</th><th>&sigma; (deg)</th></tr>";
    for (const auto& v : s["views"])
      h << "<tr><td>" << html_escape(v["name"].get<std::string>()) << "</td><td>(" << jnum(v["forward"][0], 3) << ", "
        << jnum(v["forward"][1], 3) << ", " << jnum(v["forward"][2], 3) << ")</td><td>" << jnum(v["sigma_deg"]) << "</td></tr>";
    h << "</table>";
  }

  if (rec.count("extract")) {
    const auto& s = rec["extract"].summary;
    h << "<h2>Balls</h2><table><tr><th>view</th><th>ball</th><th>centre (px)</th><th>radius (px)</th>"
         "<th>outline RMS (px)</th><th>confident</th></tr>";
    for (const auto& v : s["views"])
      for (const auto& b : v["balls"])
        h << "<tr><td>" << html_escape(v["name"].get<std::string>()) << "</td><td>" << html_escape(b["ball"].get<std::string>())
          << "</td><td>(" << jnum(b["centre_px"][0], 5) << ", " << jnum(b["centre_px"][1], 5) << ")</td><td>"
          << jnum(b["radius_px"]) << "</td><td>" << jnum(b["outline_rms_px"]) << "</td><td>"
          << num(100 * b["confident_fraction"].get<double>(), 3) << "%</td></tr>";
    h << "</table>";
  }

  if (rec.count("probe")) {
    const auto& s = rec["probe"].summary;
    const EnvMap probe = read_environment((dir / "probe.exr").string());
    const cv::Scalar mean = cv::mean(probe.pixels);
    std::vector<unsigned char> png;
    cv::imencode(".png", display_encode(probe.pixels, auto_exposure(mean[0], mean[1], mean[2])), png);
    h << "<h2>Light probe</h2><p>" << jnum(s["views"]) << " chrome views blended, "
      << num(100 * s["covered_fraction"].get<double>(), 3) << "% of the sphere seen (lat-long, tone-mapped).</p>"
      << img_tag(png, "probe");
  }

  if (rec.count("compare")) {
    const auto& s = rec["compare"].summary;
    h << "<h2>Captured vs computed</h2><p>Captured grey-ball maps against maps baked from the probe (Lambert). "
         "Errors after the global exposure / white-balance fit are errors of shape; the fitted gains are the "
         "calibration offset. Heat maps: log2 error (stops).</p>";
    // Pixels clipped in every bracket hold lower bounds; in the chrome views they are left out of
    // the probe, so light from there (a sun) is missing from the computed maps.
    long clipped = 0;
    if (rec.count("hdr"))
      for (const auto& v : rec["hdr"].summary["views"]) clipped = std::max(clipped, v.value("clipped_pixels", 0L));
    if (clipped > 0)
      h << "<p class=\"warn\"><b>Clipped pixels:</b> up to " << clipped
        << " pixel(s) of a view saturated in every bracket (lower bounds, left out of the probe). A sun "
           "reflected in a chrome ball covers a pixel or two and holds most of the light: if it is among them, "
           "the computed maps are too dark on the side it lights. Shoot shorter brackets.</p>";
    for (const auto& b : s["balls"]) {
      h << "<h3>" << html_escape(b["ball"].get<std::string>()) << "</h3>";
      if (b.contains("fit"))
        h << "<p>Fitted gains R, G, B: " << jnum(b["fit"]["gains"][0]) << ", " << jnum(b["fit"]["gains"][1]) << ", "
          << jnum(b["fit"]["gains"][2]) << " (" << jnum(b["fit"]["exposure_stops"], 3) << " stops).</p>";
      h << "<table><tr><th>view</th><th>rel RMS before</th><th>rel RMS after</th><th>log RMS after (stops)</th>"
           "<th>PSNR after (dB)</th></tr>";
      for (const auto& v : b["views"])
        h << "<tr><td>" << html_escape(v["image"].get<std::string>()) << "</td><td>" << jnum(v["before"]["relative_rms"])
          << "</td><td>" << jnum(v["after"]["relative_rms"]) << "</td><td>" << jnum(v["after"]["log_rms_stops"])
          << "</td><td>" << jnum(v["after"]["psnr_db"]) << "</td></tr>";
      h << "<tr><th>overall</th><th>" << jnum(b["overall"]["before"]["relative_rms"]) << "</th><th>"
        << jnum(b["overall"]["after"]["relative_rms"]) << "</th><th>" << jnum(b["overall"]["after"]["log_rms_stops"])
        << "</th><th>" << jnum(b["overall"]["after"]["psnr_db"]) << "</th></tr></table>";
      for (const auto& v : b["views"])
        h << "<p>" << img_tag(read_bytes(fs::path(b["folder"].get<std::string>()) / v["picture"].get<std::string>()),
                              v["image"].get<std::string>())
          << "</p>";
    }
  }

  if (rec.count("render")) {
    const auto& s = rec["render"].summary;
    h << "<h2>Turntable</h2><p>" << html_escape(s.value("mesh", "")) << " (" << jnum(s["triangles"]) << " triangles), "
      << html_escape(s.value("material", "")) << ", rendered by the runtime from maps baked from the probe; "
      << jnum(s["seconds_per_frame"], 3) << " s per frame.</p><div class=\"frames\">";
    for (const fs::path& f : rec["render"].outputs)
      if (f.extension() == ".png") h << img_tag(read_bytes(f), f.filename().string());
    h << "</div>";
  }
  h << "</body></html>\n";
  const std::string text = h.str();
  write_atomically(out, [&](const std::string& tmp) {
    std::ofstream o(tmp, std::ios::binary);
    o << text;
    if (!o) throw std::runtime_error(tmp + ": cannot write");
  });
}

}  // namespace rsibr
