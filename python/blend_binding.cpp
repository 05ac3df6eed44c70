// Reflection-space blending (runtime/blend.h): the radiance map of any view from a map set.
#include "python/bindings.h"
#include "python/numpy_mat.h"

#include "core/map_set.h"
#include "runtime/blend.h"
#include "runtime/make_warp.h"
#include "runtime/warp.h"

#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include <memory>
#include <optional>

namespace rsibr::python {

void bind_blend(py::module_& m) {
  py::class_<BlendResult>(m, "BlendResult", "The blended radiance map of a destination view.")
      .def_property_readonly("rgb", [](const BlendResult& r) { return to_array(r.rgb); },
                             "(H, W, 3) float32 RGB sphere map; 0 outside the disc (shares memory).")
      .def_property_readonly("weight", [](const BlendResult& r) { return to_array(r.weight); },
                             "(H, W) float32 total weight sum_i a_i in [0, 1]; 0 outside the disc and where the "
                             "fallback was used (the `rsibr blend` output's confidence channel).")
      .def_readonly("world_from_view", &BlendResult::world_from_view, "The destination frame T_d.")
      .def_readonly("located", &BlendResult::located, "The source views and their barycentric weights (ViewWeights).")
      .def_property_readonly("source_weights",
                             [](const BlendResult& r) {
                               py::list out;
                               for (int i = 0; i < r.located.count; ++i) out.append(to_array(r.source_weight[std::size_t(i)]));
                               return out;
                             },
                             "With source_weights=True: per located source, its (H, W) per-texel weight a_i.");

  m.def(
      "blend",
      [](const MapSet& maps, const Vec3& view, const Vec3& up, int size, const std::string& warp_name, int rings,
         double rim_fade, bool use_confidence, bool source_weights, const std::optional<ViewSet>& view_set) {
        if (!view.allFinite() || !(view.norm() > 0)) throw py::value_error("blend: view must be a non-zero direction");
        const int w = size > 0 ? size : maps.width(), h = size > 0 ? size : maps.height();
        BlendOptions options;
        options.width = w;
        options.height = h;
        options.rim_fade = rim_fade;
        options.use_confidence = use_confidence;
        options.source_weights = source_weights;
        py::gil_scoped_release release;
        std::unique_ptr<Warp> warp;
        try {
          warp = make_warp({warp_name, rings, axis_in_views(maps, up)}, w, h);
        } catch (const std::invalid_argument& e) {
          throw std::invalid_argument(std::string("blend: ") + e.what());
        }
        options.warp = warp.get();
        return blend(maps, view_set ? *view_set : maps.view_set(), view, up, options);
      },
      py::arg("maps"), py::arg("view"), py::arg("up") = Vec3(0, 1, 0), py::arg("size") = 0,
      py::arg("warp") = "precomputed", py::arg("rings") = 16, py::arg("rim_fade") = 0.4, py::arg("use_confidence") = true,
      py::arg("source_weights") = false, py::arg("view_set") = py::none(),
      "Warps and blends a MapSet to the radiance map of `view` (world, toward the viewer), as `rsibr blend` does: "
      "the view's triangle in the set's view set (`view_set`, default maps.view_set()), each of its three maps "
      "warped in reflection space with its own warp, faded near its singularity (rim_fade; 0 disables) and "
      "normalised per texel. size: the output's side (0: the set's size). warp: 'exact', 'precomputed' (same "
      "result, cached directions), 'tessellated' (the paper's disc mesh of `rings` rings) or 'double-indirection' "
      "(screen and parametric tables; a rotation about `up` is an offset into them). Releases the GIL.");
}

}  // namespace rsibr::python
