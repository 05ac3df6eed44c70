// BRDFs from specs (bake/brdf_spec.h) and baking computed map sets (bake/map_set_bake.h).
#include "python/bindings.h"

#include "bake/brdf_lobes.h"
#include "bake/brdf_spec.h"
#include "bake/integrator.h"
#include "bake/map_set_bake.h"
#include "core/env_map.h"
#include "formats/map_set.h"
#include "core/view_set.h"

#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include <memory>

namespace rsibr::python {
namespace {

std::shared_ptr<const Brdf> brdf_of(const py::object& brdf) {
  if (py::isinstance<py::str>(brdf)) return parse_brdf(brdf.cast<std::string>());
  return brdf.cast<std::shared_ptr<Brdf>>();
}

ViewSet views_of(const py::object& views) {
  if (py::isinstance<py::str>(views)) return ViewSet::named(views.cast<std::string>());
  return views.cast<ViewSet>();
}

}  // namespace

void bind_bake(py::module_& m) {
  py::class_<Brdf, std::shared_ptr<Brdf>>(
      m, "Brdf",
      "An isotropic BRDF in the local shading frame (normal +z; wo toward the viewer, wi toward the light, unit). "
      "Made by parse_brdf or load_brdf from a spec: {type: lambert, albedo: [r, g, b]}, phong, blinn_phong, "
      "{type: ggx, roughness: a, fresnel: F}, clearcoat, or {type: lobe, part: normal|mirror, of: B}.")
      .def_property_readonly("spec", &Brdf::spec, "The BRDF as one line of YAML that parse_brdf reads back exactly.")
      .def("eval", &Brdf::eval, py::arg("wo"), py::arg("wi"),
           "f_r(wo, wi) cos(theta_i), RGB (the cosine IS included); 0 below the horizon.")
      .def("pdf", &Brdf::pdf, py::arg("wo"), py::arg("wi"), "Solid-angle density of the BRDF's sampler.")
      .def("albedo", &Brdf::albedo, py::arg("wo"),
           "Directional albedo: the integral of eval(wo, .) over the hemisphere, RGB (a white furnace's answer).")
      .def_property_readonly(
          "central_direction", [](const Brdf& b) { return std::string(to_string(b.central_direction())); },
          "'normal' or 'mirror': the direction the lobe follows (the warp of its maps).")
      .def(
          "has_lobe",
          [](const Brdf& b, const std::string& part) { return b.has_lobe(central_direction_from_string(part)); },
          py::arg("part"), "True when the 'normal' or 'mirror' part is not identically zero.")
      .def("lobe_width", &Brdf::lobe_width, py::arg("wo"),
           "Half-angle (radians) of the cone holding 90% of the energy.")
      .def("__repr__", [](const Brdf& b) { return "Brdf(" + b.spec() + ")"; });

  m.def(
      "parse_brdf", [](const std::string& text) { return std::shared_ptr<Brdf>(parse_brdf(text)); }, py::arg("spec"),
      "A Brdf from YAML text; ValueError naming the key path (e.g. 'brdf.fresnel.f0: ...') for a bad spec.");
  m.def(
      "load_brdf",
      [](const std::string& path) {
        check_input_file(path);
        return std::shared_ptr<Brdf>(load_brdf(path));
      },
      py::arg("path"), "A Brdf from a YAML file; errors are prefixed with the file name.");

  m.def(
      "bake",
      [](const py::object& brdf_in, const EnvMap& environment, const py::object& views_in, int res,
         const std::string& method, int samples, std::uint64_t seed, int reference_width, bool normalise_albedo,
         const std::string& environment_name) {
        const std::shared_ptr<const Brdf> brdf = brdf_of(brdf_in);
        const ViewSet views = views_of(views_in);
        if (environment.pixels.empty()) throw py::value_error("bake: the environment has no pixels");
        MapSetBakeOptions options;
        options.res = res;
        options.integrator.samples = samples;
        options.integrator.seed = seed;
        options.integrator.reference_width = reference_width;
        options.normalise_albedo = normalise_albedo;
        options.environment_name = environment_name;
        py::gil_scoped_release release;
        const auto integrator = make_integrator(method, environment);
        return bake_map_set(*brdf, *integrator, views, options);
      },
      py::arg("brdf"), py::arg("environment"), py::arg("views") = "icosa", py::arg("res") = 128,
      py::arg("method") = "mis", py::arg("samples") = 64, py::arg("seed") = 0, py::arg("reference_width") = 0,
      py::arg("normalise_albedo") = false, py::arg("environment_name") = "",
      "Bakes a computed MapSet, as `rsibr bake` does: for every view of `views` (a ViewSet or a name such as "
      "'icosa', '42', 'fib20'), a res x res sphere map of the lighting integral int L_i(w) f_r(v, w) max(0, n.w) dw "
      "of `brdf` (a Brdf or a YAML spec string) under `environment`. method: 'reference' (quadrature over every "
      "texel, at most reference_width wide; exact), 'mis' or 'fis' (samples per texel, seed: the same inputs give "
      "the same bytes) or 'sh' (Lambert only). normalise_albedo stores L / A(n.v) with the albedo table. "
      "environment_name is recorded as the rsibr.environment attribute. Releases the GIL while it runs.");
}

}  // namespace rsibr::python
