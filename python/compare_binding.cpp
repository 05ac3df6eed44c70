// Comparing two map sets or two environments (compare/map_compare.h): the numbers `rsibr compare` reports.
#include "python/bindings.h"
#include "python/numpy_mat.h"

#include "compare/map_compare.h"

#include <pybind11/eigen.h>
#include <pybind11/stl.h>

namespace rsibr::python {

void bind_compare(py::module_& m) {
  py::class_<ErrorMetrics>(m, "ErrorMetrics", "Weighted error of A against the reference B.")
      .def_readonly("relative_rms", &ErrorMetrics::relative_rms, "sqrt(sum w|a-b|^2 / sum w|b|^2).")
      .def_readonly("log_rms_stops", &ErrorMetrics::log_rms_stops, "RMS of log2((a+eps)/(b+eps)), stops.")
      .def_readonly("mse", &ErrorMetrics::mse, "Weighted mean squared error.")
      .def_readonly("psnr_db", &ErrorMetrics::psnr_db, "PSNR against the peak, dB (capped at 144.5).")
      .def_readonly("psnr_capped", &ErrorMetrics::psnr_capped, "The MSE is at or below the float32 floor.")
      .def_readonly("weight", &ErrorMetrics::weight, "Sum of the texel weights.")
      .def_readonly("texels", &ErrorMetrics::texels, "Texels with weight > 0.")
      .def_readonly("mean_a", &ErrorMetrics::mean_a, "Weighted channel means of A.")
      .def_readonly("mean_b", &ErrorMetrics::mean_b, "Weighted channel means of B.")
      .def("__repr__", [](const ErrorMetrics& e) {
        return "ErrorMetrics(relative_rms=" + std::to_string(e.relative_rms) +
               ", log_rms_stops=" + std::to_string(e.log_rms_stops) + ", psnr_db=" + std::to_string(e.psnr_db) + ")";
      });
  py::class_<GainFit>(m, "GainFit", "The global exposure / white-balance fit g_c a_c ~ b_c (Cauchy loss).")
      .def_readonly("gains", &GainFit::gains, "Per-channel gains applied to A.")
      .def_readonly("exposure_stops", &GainFit::exposure_stops, "log2 of the gains' Rec.709 luminance.")
      .def_readonly("chroma", &GainFit::chroma, "gains / 2^exposure_stops: the white-balance part.")
      .def_readonly("texels_used", &GainFit::texels_used)
      .def_readonly("iterations", &GainFit::iterations)
      .def_readonly("converged", &GainFit::converged)
      .def_readonly("initial_cost", &GainFit::initial_cost)
      .def_readonly("final_cost", &GainFit::final_cost);
  py::class_<ErrorSettings>(m, "ErrorSettings", "The eps of the log error and the PSNR's peak used for every pair.")
      .def_readonly("log_epsilon", &ErrorSettings::log_epsilon)
      .def_readonly("psnr_peak", &ErrorSettings::psnr_peak);
  py::class_<PairComparison>(m, "PairComparison", "One compared pair: a view of A and its partner in B.")
      .def_readonly("name", &PairComparison::name, "'view.NNN' (A's part) or 'environment'.")
      .def_readonly("index_a", &PairComparison::index_a)
      .def_readonly("index_b", &PairComparison::index_b)
      .def_readonly("view", &PairComparison::view, "A's view direction (zero for environments).")
      .def_readonly("angle_deg", &PairComparison::angle_deg, "Angle between A's and B's view directions.")
      .def_readonly("frame_angle_deg", &PairComparison::frame_angle_deg, "Rotation between A's and B's frames.")
      .def_readonly("b_resampled", &PairComparison::b_resampled, "B was resampled into A's frame.")
      .def_readonly("before", &PairComparison::before, "ErrorMetrics before the gain fit.")
      .def_readonly("after", &PairComparison::after, "ErrorMetrics after it.")
      .def_property_readonly(
          "a", [](const PairComparison& p) { return to_array(p.images.a); }, "A's (H, W, 3) image.")
      .def_property_readonly(
          "b", [](const PairComparison& p) { return to_array(p.images.b); }, "B's (H, W, 3) image, in A's frame.")
      .def_property_readonly(
          "weight", [](const PairComparison& p) { return to_array(p.images.weight); }, "(H, W) texel weights.");
  py::class_<Comparison>(m, "Comparison", "The result of compare(): per pair and overall, before and after the fit.")
      .def_readonly("pairs", &Comparison::pairs, "PairComparison per pair, in the smaller set's order.")
      .def_readonly("before", &Comparison::before, "Overall ErrorMetrics before the fit.")
      .def_readonly("after", &Comparison::after, "Overall ErrorMetrics after the fit.")
      .def_readonly("fit", &Comparison::fit, "The GainFit, or None with fit=False.")
      .def_readonly("settings", &Comparison::settings, "The ErrorSettings used.");

  m.def(
      "compare",
      [](const py::object& a, const py::object& b, bool fit, double log_eps, double psnr_peak, double view_tolerance,
         double loss_scale, long fit_texels, const std::string& name_a, const std::string& name_b) {
        CompareOptions o;
        o.name_a = name_a;
        o.name_b = name_b;
        o.log_epsilon_fraction = log_eps;
        o.psnr_peak = psnr_peak;
        o.view_tolerance_deg = view_tolerance;
        o.fit = fit;
        o.fit_options.loss_scale = loss_scale;
        o.fit_options.max_texels = fit_texels;
        if (py::isinstance<MapSet>(a) && py::isinstance<MapSet>(b)) {
          const MapSet& ma = a.cast<const MapSet&>();
          const MapSet& mb = b.cast<const MapSet&>();
          py::gil_scoped_release release;
          return compare_map_sets(ma, mb, o);
        }
        if (py::isinstance<EnvMap>(a) && py::isinstance<EnvMap>(b)) {
          const EnvMap& ea = a.cast<const EnvMap&>();
          const EnvMap& eb = b.cast<const EnvMap&>();
          py::gil_scoped_release release;
          return compare_environments(ea, eb, o);
        }
        throw py::value_error("compare: give two MapSets or two Environments");
      },
      py::arg("a"), py::arg("b"), py::arg("fit") = true, py::arg("log_eps") = 1e-2, py::arg("psnr_peak") = 0.0,
      py::arg("view_tolerance") = 0.5, py::arg("loss_scale") = 0.1, py::arg("fit_texels") = 1L << 17,
      py::arg("name_a") = "A", py::arg("name_b") = "B",
      "Compares A against the reference B (two MapSets, views paired by direction within view_tolerance degrees, "
      "or two Environments of one layout and size), as `rsibr compare` does, with its options: relative RMS, log "
      "RMS (eps = log_eps x B's weighted median level) and PSNR (peak psnr_peak, or B's largest weighted value), "
      "per pair and overall, before and after a global gain fit (fit=False skips it; loss_scale, fit_texels). "
      "ValueError names name_a / name_b for views without a partner, mismatched sizes or no weight.");
}

}  // namespace rsibr::python
