#include "compare/comparison_report.h"

#include "compare/compare_pictures.h"
#include "core/preview_exposure.h"

namespace rsibr {

nlohmann::json error_metrics_json(const ErrorMetrics& m) {
  return {{"relative_rms", m.relative_rms},
          {"log_rms_stops", m.log_rms_stops},
          {"psnr_db", m.psnr_db},
          {"psnr_capped", m.psnr_capped},
          {"mse", m.mse},
          {"mean_a", m.mean_a},
          {"mean_b", m.mean_b}};
}

ComparisonImages comparison_images(const Comparison& c, double heat_max, float exposure_stops) {
  ComparisonImages out;
  const std::array<double, 3> gains = c.fit ? c.fit->gains : std::array<double, 3>{1, 1, 1};
  std::vector<cv::Mat> weights, shown, weighted;
  for (const PairComparison& p : c.pairs) {
    out.a_fitted.push_back(c.fit ? apply_gains(p.images.a, gains) : p.images.a);
    out.errors.push_back(log_error_image(p.images.a, p.images.b, p.images.weight, c.settings.log_epsilon, gains));
    weights.push_back(p.images.weight);
    shown.push_back(p.images.b);
    weighted.push_back(p.images.weight > 0);
  }
  out.heat_max = heat_max > 0 ? heat_max : heat_scale_max(out.errors, weights);
  out.exposure_stops = std::isfinite(exposure_stops) ? exposure_stops : preview_exposure(shown, weighted);
  return out;
}

nlohmann::json comparison_json(const Comparison& c, const ComparisonImages& images, bool map_sets) {
  nlohmann::json j;
  j["settings"] = {
      {"log_epsilon", c.settings.log_epsilon}, {"psnr_peak", c.settings.psnr_peak}, {"psnr_cap_db", kPsnrCapDb}};
  j["overall"] = {{"before", error_metrics_json(c.before)},
                  {"after", error_metrics_json(c.after)},
                  {"texels", c.before.texels},
                  {"weight", c.before.weight}};
  if (c.fit) {
    j["fit"] = {{"gains", c.fit->gains},
                {"exposure_stops", c.fit->exposure_stops},
                {"chroma", c.fit->chroma},
                {"model", "g_c a_c ~ b_c; residual ln(g a' + eps) - ln(b' + eps); Cauchy loss"},
                {"texels_used", c.fit->texels_used},
                {"iterations", c.fit->iterations},
                {"converged", c.fit->converged},
                {"initial_cost", c.fit->initial_cost},
                {"final_cost", c.fit->final_cost}};
  } else {
    j["fit"] = nullptr;
  }
  j["heat_map"] = {{"quantity", std::string("sqrt(mean over R,G,B of log2((a' + eps)/(b' + eps))^2), A ") +
                                    (c.fit ? "after the fit" : "as read")},
                   {"unit", "stops"},
                   {"colormap", "viridis"},
                   {"min", 0.0},
                   {"max", images.heat_max},
                   {"ticks", {0.0, 0.5 * images.heat_max, images.heat_max}},
                   {"no_weight_colour_rgb", {kNoWeightColour[2], kNoWeightColour[1], kNoWeightColour[0]}},
                   {"display_exposure_stops", images.exposure_stops}};
  nlohmann::json views = nlohmann::json::array();
  for (const PairComparison& p : c.pairs) {
    nlohmann::json jv = {{"name", p.name},
                         {"texels", p.before.texels},
                         {"weight", p.before.weight},
                         {"before", error_metrics_json(p.before)},
                         {"after", error_metrics_json(p.after)}};
    if (map_sets) {
      jv["a_part"] = p.index_a;
      jv["b_part"] = p.index_b;
      jv["view"] = {p.view.x(), p.view.y(), p.view.z()};
      jv["angle_deg"] = p.angle_deg;
      jv["frame_angle_deg"] = p.frame_angle_deg;
      jv["b_resampled_to_a_frame"] = p.b_resampled;
    }
    views.push_back(jv);
  }
  j["views"] = views;
  return j;
}

cv::Mat comparison_panel(const Comparison& c, const ComparisonImages& images, std::size_t i, const std::string& title,
                         const std::string& a_label, const std::string& b_label) {
  const PairComparison& p = c.pairs.at(i);
  SideBySideInput in;
  in.a_rgb = images.a_fitted.at(i);
  in.b_rgb = p.images.b;
  in.error = images.errors.at(i);
  in.weight = p.images.weight;
  in.exposure_stops = images.exposure_stops;
  in.heat_max = images.heat_max;
  in.title = title;
  in.a_label = a_label;
  in.b_label = b_label;
  in.heat_label = "log2 error";
  return side_by_side(in);
}

}  // namespace rsibr
