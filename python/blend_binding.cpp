// Reflection-space blending (runtime/blend.h): the radiance map of any view from a map set.
#include "python/bindings.h"
#include "python/numpy_mat.h"

#include "formats/map_set.h"
#include "runtime/blend.h"
#include "runtime/blend_engine.h"
#include "runtime/make_warp.h"
#include "runtime/warp.h"

#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include <memory>
#include <optional>
#include <optional>
#include <string>

#include <tbb/parallel_for.h>

namespace rsibr::python {

namespace {

// A blend engine for Python: owns its view set (the MapSet is kept alive by pybind11) and the last
// warp it built, so that a turntable of map() calls lays out the sources and builds a warp once.
class PyBlendEngine {
 public:
  PyBlendEngine(const MapSet& maps, double rim_fade, bool use_confidence, const std::optional<ViewSet>& view_set)
      : maps_(maps), view_set_(view_set ? *view_set : maps.view_set()) {
    BlendRule rule;
    rule.rim_fade = rim_fade;
    rule.use_confidence = use_confidence;
    engine_ = std::make_unique<BlendEngine>(maps_, view_set_, rule);
  }
  BlendResult map(const Vec3& view, const Vec3& up, int size, const std::string& warp_name, int rings,
                  bool source_weights) {
    if (!view.allFinite() || !(view.norm() > 0)) throw py::value_error("blend: view must be a non-zero direction");
    MapRequest request;
    request.width = size > 0 ? size : maps_.width();
    request.height = size > 0 ? size : maps_.height();
    request.source_weights = source_weights;
    py::gil_scoped_release release;
    const std::string key = warp_name + "/" + std::to_string(rings) + "/" + std::to_string(request.width) + "x" +
                            std::to_string(request.height);
    if (!warp_ || key != warp_key_) {
      try {
        warp_ = make_warp({warp_name, rings, axis_in_views(maps_, up)}, request.width, request.height);
      } catch (const std::invalid_argument& e) {
        throw std::invalid_argument(std::string("blend: ") + e.what());
      }
      warp_key_ = key;
    }
    request.warp = warp_.get();
    return engine_->map(view, up, request);
  }
  // Per row of v (N x 3) and n (N x 3), world, unit: the radiance (N x 3) and the weight (N); with
  // dn_dx and dn_dy (N x 3 each, world), at that footprint (BlendEngine::Footprint).
  using Rows = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
  py::tuple radiance(const Rows& v, const Rows& n, const std::optional<Rows>& dn_dx,
                     const std::optional<Rows>& dn_dy) const {
    if (v.rows() != n.rows()) throw py::value_error("radiance: v and n must have the same number of rows");
    if (!v.allFinite() || !n.allFinite()) throw py::value_error("radiance: v and n must be finite");
    if (dn_dx.has_value() != dn_dy.has_value())
      throw py::value_error("radiance: give both dn_dx and dn_dy, or neither");
    if (dn_dx && (dn_dx->rows() != v.rows() || dn_dy->rows() != v.rows()))
      throw py::value_error("radiance: dn_dx and dn_dy must have as many rows as v");
    if (dn_dx && (!dn_dx->allFinite() || !dn_dy->allFinite()))
      throw py::value_error("radiance: dn_dx and dn_dy must be finite");
    Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> L(v.rows(), 3);
    Eigen::VectorXd w(v.rows());
    {
      py::gil_scoped_release release;
      engine_->prepare_all();
      tbb::parallel_for(tbb::blocked_range<Eigen::Index>(0, v.rows(), 256), [&](const auto& range) {
        int hint = -1;
        for (Eigen::Index i = range.begin(); i != range.end(); ++i) {
          const Vec3 vi = v.row(i).transpose().normalized(), ni = n.row(i).transpose().normalized();
          double wi = 0;
          const ViewWeights located = engine_->locate(vi, &hint);
          if (dn_dx) {
            BlendEngine::Footprint fp;
            fp.dn_dx = dn_dx->row(i).transpose();
            fp.dn_dy = dn_dy->row(i).transpose();
            L.row(i) = engine_->radiance(located, vi, ni, fp, &wi).transpose();
          } else {
            L.row(i) = engine_->radiance(located, vi, ni, &wi).transpose();
          }
          w[i] = wi;
        }
      });
    }
    return py::make_tuple(L, w);
  }
  ViewWeights locate(const Vec3& v) const { return engine_->locate(v); }

 private:
  const MapSet& maps_;
  ViewSet view_set_;
  std::unique_ptr<BlendEngine> engine_;
  std::unique_ptr<Warp> warp_;
  std::string warp_key_;
};

}  // namespace

void bind_blend(py::module_& m) {
  py::class_<BlendResult>(m, "BlendResult", "The blended radiance map of a destination view.")
      .def_property_readonly(
          "rgb", [](const BlendResult& r) { return to_array(r.rgb); },
          "(H, W, 3) float32 RGB sphere map; 0 outside the disc (shares memory).")
      .def_property_readonly(
          "weight", [](const BlendResult& r) { return to_array(r.weight); },
          "(H, W) float32 total weight sum_i a_i in [0, 1]; 0 outside the disc and where the "
          "fallback was used (the `rsibr blend` output's confidence channel).")
      .def_readonly("world_from_view", &BlendResult::world_from_view, "The destination frame T_d.")
      .def_readonly("located", &BlendResult::located, "The source views and their barycentric weights (ViewWeights).")
      .def_property_readonly(
          "source_weights",
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
      py::arg("warp") = "precomputed", py::arg("rings") = 16, py::arg("rim_fade") = 0.4,
      py::arg("use_confidence") = true, py::arg("source_weights") = false, py::arg("view_set") = py::none(),
      "Warps and blends a MapSet to the radiance map of `view` (world, toward the viewer), as `rsibr blend` does: "
      "the view's triangle in the set's view set (`view_set`, default maps.view_set()), each of its three maps "
      "warped in reflection space with its own warp, faded near its singularity (rim_fade; 0 disables) and "
      "normalised per texel. size: the output's side (0: the set's size). warp: 'exact', 'precomputed' (same "
      "result, cached directions), 'tessellated' (the paper's disc mesh of `rings` rings) or 'double-indirection' "
      "(screen and parametric tables; a rotation about `up` is an offset into them). Releases the GIL.");

  py::class_<PyBlendEngine>(m, "BlendEngine",
                            "A map set and its blend rule, held for many blends: each source is laid out once "
                            "(the first time it is used) and the warp of the last map() is kept, so a turntable "
                            "of views costs one blend a frame. The same results as blend(). Keeps `maps` alive.")
      .def(py::init<const MapSet&, double, bool, const std::optional<ViewSet>&>(), py::arg("maps"),
           py::arg("rim_fade") = 0.4, py::arg("use_confidence") = true, py::arg("view_set") = py::none(),
           py::keep_alive<1, 2>())
      .def("map", &PyBlendEngine::map, py::arg("view"), py::arg("up") = Vec3(0, 1, 0), py::arg("size") = 0,
           py::arg("warp") = "precomputed", py::arg("rings") = 16, py::arg("source_weights") = false,
           "The destination map of `view` (as blend()). Releases the GIL.")
      .def("radiance", &PyBlendEngine::radiance, py::arg("v"), py::arg("n"), py::arg("dn_dx") = py::none(),
           py::arg("dn_dy") = py::none(),
           "Radiance toward viewer directions v (N x 3, world, from the surface to the viewer) from normals "
           "n (N x 3, world): the blend for each (v, n) pair without a destination map (the renderer's "
           "per-pixel mode). With dn_dx and dn_dy (N x 3, world: how the normal changes across one pixel), "
           "each source is read at that footprint's level of detail (MIP levels; the MIP-mask blend for sets "
           "of mixed resolution), as `rsibr render --lod` does. Returns (radiance N x 3, weight N). v and n "
           "are normalised. Releases the GIL.")
      .def("locate", &PyBlendEngine::locate, py::arg("v"), "The view set's triangle and weights for direction v.");
}

}  // namespace rsibr::python
