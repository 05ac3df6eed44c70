#include "pipeline/response_choice_html.h"

#include "pipeline/html_report.h"

#include <sstream>

namespace rsibr {

std::string response_choice_html(const nlohmann::json& r) {
  if (!r.is_object() || r.empty()) return "";
  std::ostringstream h;
  h.precision(3);
  h << "<p>Chosen by held-out error: <b>" << html_escape(r.value("chosen", "")) << "</b>";
  if (r.contains("margin_sigmas") && r["margin_sigmas"].is_number())
    h << ", " << r["margin_sigmas"].get<double>() << " standard errors of the held-out noise from another choice";
  h << "; " << r.value("views", 0) << " views, " << r.value("train_samples", 0) << " + "
    << r.value("held_out_samples", 0) << " samples (training + held out).";
  if (r.contains("saturation_code"))
    h << " Saturation codes R, G, B: " << r["saturation_code"][0] << ", " << r["saturation_code"][1] << ", "
      << r["saturation_code"][2] << " (" << html_escape(r.value("saturation_source", "")) << ").";
  h << "</p>";
  if (r.value("near_tie", false))
    h << "<p style=\"color:#a40\"><b>Warning:</b> " << html_escape(r.value("warning", "")) << "</p>";
  h << "<table><tr><th>model</th><th>curves</th><th>held-out error</th><th>excess (sigma)</th><th>within the noise</th></tr>";
  for (const auto& c : r.value("candidates", nlohmann::json::array())) {
    std::string name = c.value("model", "");
    if (c.contains("parameters") && c["parameters"].contains("degree"))
      name += " " + std::to_string(c["parameters"]["degree"].get<int>());
    if (c.contains("parameters") && c["parameters"].contains("lambda")) {
      std::ostringstream l;
      l << " lambda " << c["parameters"]["lambda"].get<double>();
      name += l.str();
    }
    h << "<tr><td>" << html_escape(name) << "</td><td>" << (c.value("shared", false) ? "shared" : "per channel")
      << "</td><td>";
    if (c["held_out_error"].is_number())
      h << c["held_out_error"].get<double>();
    else
      h << "rejected";
    h << "</td><td>";
    if (c.contains("excess_sigmas") && c["excess_sigmas"].is_number()) h << c["excess_sigmas"].get<double>();
    h << "</td><td>" << (c.value("tied", false) ? "yes" : "") << "</td></tr>";
  }
  h << "</table>";
  return h.str();
}

}  // namespace rsibr
