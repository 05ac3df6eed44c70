#include "pipeline/light_sources_report.h"

#include "core/colour.h"
#include "formats/exr_io.h"
#include "pipeline/html_report.h"
#include "formats/image_codecs.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

namespace rsibr {

namespace fs = std::filesystem;

namespace {

std::string fixed(double v, int digits) {
  if (!std::isfinite(v)) return "-";
  std::ostringstream s;
  s << std::fixed << std::setprecision(digits) << v;
  return s.str();
}

std::string sci(double v) {
  if (!std::isfinite(v)) return "-";
  std::ostringstream s;
  s << std::setprecision(3) << v;
  return s.str();
}

std::string rgb(const nlohmann::json& v, bool percent = false) {
  if (!v.is_array() || v.size() < 3) return "-";
  std::string out;
  for (int k = 0; k < 3; ++k) {
    const double x = v[std::size_t(k)].get<double>();
    out += (k ? " / " : "") + (percent ? fixed(100 * x, 1) + "%" : sci(x));
  }
  return out;
}

std::string where(const nlohmann::json& j) {
  return "azimuth " + fixed(j.value("azimuth_deg", 0.0), 1) + "&deg;, elevation " +
         fixed(j.value("elevation_deg", 0.0), 1) + "&deg;";
}

// A crop of the lat-long probe around a direction (33 x 33 texels, wrapped in longitude, clamped at
// the poles), magnified 6x by nearest texel, at `stops`.
std::vector<unsigned char> crop_png(const EnvMap& probe, const nlohmann::json& dir, float stops) {
  const Vec3 d(dir[0].get<double>(), dir[1].get<double>(), dir[2].get<double>());
  const Vec2 p = probe.layout.pixel(d);
  const int W = probe.layout.width(), H = probe.layout.height(), half = 16;
  cv::Mat crop(2 * half + 1, 2 * half + 1, CV_32FC3, cv::Scalar::all(0));
  for (int r = 0; r < crop.rows; ++r)
    for (int c = 0; c < crop.cols; ++c) {
      const int rr = std::clamp(int(std::lround(p.y())) - half + r, 0, H - 1);
      const int cc = ((int(std::lround(p.x())) - half + c) % (W - 1) + (W - 1)) % (W - 1);
      const float* px = probe.pixels.ptr<float>(rr) + cc * probe.channels();
      crop.at<cv::Vec3f>(r, c) = cv::Vec3f(px[0], px[1], px[2]);
    }
  cv::Mat big;
  cv::resize(crop, big, cv::Size(), 6, 6, cv::INTER_NEAREST);
  std::vector<unsigned char> png;
  encode_image(".png", display_encode(big, stops), png);
  return png;
}

std::string img(const std::vector<unsigned char>& png, const std::string& alt) {
  return "<img alt=\"" + html_escape(alt) + "\" src=\"data:image/png;base64," + base64_encode(png) + "\">";
}

}  // namespace

std::string light_sources_warning(const nlohmann::json& s) {
  if (!s.contains("regions") || s["regions"].empty()) return "";
  std::ostringstream h;
  h << "<p class=\"warn\"><b>Clipped light:</b> ";
  const auto& sources = s.value("sources", nlohmann::json::array());
  const nlohmann::json measured = s.value("measured_integral", nlohmann::json::array({0, 0, 0}));
  for (const auto& src : sources) {
    // This source's share of the final probe's light.
    nlohmann::json share = nlohmann::json::array();
    for (int k = 0; k < 3; ++k) {
      const double p = src["power"][std::size_t(k)].get<double>();
      const double total = measured[std::size_t(k)].get<double>() + s["recovered_power"][std::size_t(k)].get<double>();
      share.push_back(total > 0 ? p / total : 0.0);
    }
    std::string balls;
    for (const auto& b : src["balls"]) balls += (balls.empty() ? "" : ", ") + html_escape(b.get<std::string>());
    h << "the source at " << where(src)
      << " was clipped in every bracket of every chrome view that saw it; without it the "
      << "probe misses " << rgb(share, true) << " (R / G / B) of the light. Recovered from the "
      << (balls.empty() ? "-" : balls) << " ball (" << src["views"].size() << " views): power " << rgb(src["power"])
      << " &plusmn; " << rgb(src["power_sigma"]) << ", direction &plusmn; "
      << fixed(src.value("direction_sigma_deg", 0.0), 2) << "&deg;. ";
  }
  for (const auto& r : s["regions"]) {
    if (r.value("recovered", false)) continue;
    h << "The clipped region at " << where(r) << " (" << sci(r.value("solid_angle_sr", 0.0))
      << " sr) was not recovered: " << html_escape(r.value("note", std::string("-"))) << ". ";
  }
  if (sources.size() < s["regions"].size())
    h << rgb(s.value("lower_bound_fraction", nlohmann::json::array({0, 0, 0})), true)
      << " (R / G / B) of the probe's light is only a lower bound there (the probe keeps the clipped values; the "
         "light may be far brighter), so the computed maps are too dark on the side it lights; shoot shorter "
         "brackets, add a grey ball, or an ND filter.";
  h << "</p>";
  return h.str();
}

std::string light_sources_section(const fs::path& dir, const nlohmann::json& s) {
  if (!s.contains("regions") || s["regions"].empty()) return "";
  std::ostringstream h;
  h << "<h2>Clipped light sources</h2><p>" << s["regions"].size() << " region(s) of the probe, "
    << fixed(100 * s.value("clipped_fraction", 0.0), 3)
    << "% of the sphere, were clipped in every bracket of every chrome "
    << "view that saw them. Each was modelled as a compact source (a disc) whose power was solved so that the grey"
    << (s.value("glossy_used", false) ? " and glossy balls" : " ball")
    << " computed from the probe match the captured ones "
    << "in every view (robust, non-negative, the probe's measured part held fixed; sigma: the larger of the fit's "
    << "covariance and the spread of leave-one-view-out solves).";
  if (!s.value("enabled", true)) h << " <b>Recovery was off</b> (--no-sources): the probe keeps them clipped.";
  h << "</p>";
  const auto& sources = s.value("sources", nlohmann::json::array());
  if (!sources.empty()) {
    h << "<table><tr><th>source</th><th>direction</th><th>&sigma; dir (&deg;)</th><th>radius (&deg;)</th>"
         "<th>solid angle (sr)</th><th>radiance R / G / B</th><th>power R / G / B</th><th>&sigma; power</th>"
         "<th>from</th><th>views</th></tr>";
    int i = 0;
    for (const auto& src : sources) {
      std::string balls, views;
      for (const auto& b : src["balls"]) balls += (balls.empty() ? "" : ", ") + b.get<std::string>();
      for (const auto& v : src["views"]) views += (views.empty() ? "" : ", ") + v.get<std::string>();
      h << "<tr><td>" << i++ << "</td><td>" << where(src) << "</td><td>"
        << fixed(src.value("direction_sigma_deg", 0.0), 2) << "</td><td>" << fixed(src.value("radius_deg", 0.0), 2)
        << (src.value("radius_fitted", false) ? "" : " (not resolved)") << "</td><td>"
        << sci(src.value("solid_angle_sr", 0.0)) << "</td><td>" << rgb(src["radiance"]) << "</td><td>"
        << rgb(src["power"]) << "</td><td>" << rgb(src["power_sigma"]) << "</td><td>" << html_escape(balls)
        << "</td><td>" << html_escape(views) << "</td></tr>";
    }
    h << "</table><p>Measured probe's light " << rgb(s["measured_integral"]) << "; recovered "
      << rgb(s["recovered_power"]) << " &plusmn; " << rgb(s["recovered_power_sigma"]) << ": "
      << rgb(s["missing_fraction"], true)
      << " (R / G / B) of the final probe's light was missing from the measured one.</p>";
  }
  for (const auto& note : s.value("notes", nlohmann::json::array()))
    h << "<p class=\"warn\">" << html_escape(note.get<std::string>()) << "</p>";
  const auto& residuals = s.value("residuals", nlohmann::json::array());
  if (!residuals.empty() && !sources.empty()) {
    h << "<p>Captured balls against the balls computed from the probe (relative RMS over trusted texels, no gain fitted), "
         "before and after the recovery:</p><table><tr><th>ball</th><th>view</th><th>before</th><th>after</th></tr>";
    for (const auto& b : residuals) {
      for (const auto& v : b["views"])
        h << "<tr><td>" << html_escape(b["ball"].get<std::string>()) << "</td><td>"
          << html_escape(v["name"].get<std::string>()) << "</td><td>" << fixed(v["before"].get<double>(), 4)
          << "</td><td>" << fixed(v["after"].get<double>(), 4) << "</td></tr>";
      h << "<tr><th>" << html_escape(b["ball"].get<std::string>()) << "</th><th>all</th><th>"
        << fixed(b["before"].get<double>(), 4) << "</th><th>" << fixed(b["after"].get<double>(), 4) << "</th></tr>";
    }
    h << "</table>";
  }
  // Before / after around each source and each region not recovered.
  if (fs::is_regular_file(dir / "probe-measured.exr") && fs::is_regular_file(dir / "probe.exr")) {
    const EnvMap before = read_environment((dir / "probe-measured.exr").string());
    const EnvMap after = read_environment((dir / "probe.exr").string());
    std::vector<std::pair<std::string, nlohmann::json>> places;
    for (const auto& src : sources) places.push_back({"source at " + where(src), src["direction"]});
    for (const auto& r : s["regions"])
      if (!r.value("recovered", false)) places.push_back({"clipped region at " + where(r), r["direction"]});
    for (const auto& [label, d] : places) {
      // Exposure: the brightest texel of the final probe's crop at display white.
      double peak = 0;
      const Vec2 p = after.layout.pixel(Vec3(d[0].get<double>(), d[1].get<double>(), d[2].get<double>()));
      for (int r = -16; r <= 16; ++r)
        for (int c = -16; c <= 16; ++c) {
          const int rr = std::clamp(int(std::lround(p.y())) + r, 0, after.layout.height() - 1);
          const int cc = ((int(std::lround(p.x())) + c) % (after.layout.width() - 1) + (after.layout.width() - 1)) %
                         (after.layout.width() - 1);
          const float* px = after.pixels.ptr<float>(rr) + cc * after.channels();
          peak = std::max({peak, double(px[0]), double(px[1]), double(px[2])});
        }
      const float stops = peak > 0 ? float(-std::log2(peak)) : 0.f;
      h << "<p>" << label << " (33 x 33 probe texels, exposure " << fixed(stops, 1) << " stops): measured "
        << img(crop_png(before, d, stops), "measured") << " with the recovered source "
        << img(crop_png(after, d, stops), "recovered") << "</p>";
    }
  }
  return h.str();
}

}  // namespace rsibr
