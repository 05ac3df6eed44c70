// Map sets (formats/map_set.h): one sphere map per view, with their attributes, and their files.
#include "python/bindings.h"
#include "python/numpy_mat.h"

#include "formats/map_set.h"

#include <pybind11/eigen.h>
#include <pybind11/stl.h>

namespace rsibr::python {

void bind_map_set(py::module_& m) {
  py::class_<MapView>(m, "MapView",
                      "One radiance sphere map of a map set: texel p holds the radiance leaving a surface with normal "
                      "world_from_view @ g_normal(p) toward a viewer at infinity along `view` (rsibr.sphere_map).")
      .def(py::init([](const py::object& rgb, const Vec3& view, const std::optional<Mat3>& world_from_view,
                       std::string warp, std::string source, std::string material, const py::object& confidence,
                       const py::object& clipped, std::map<std::string, std::string> attributes,
                       std::vector<float> albedo) {
             MapView v;
             v.rgb = to_mat(rgb, 3, "rgb");
             v.view = view.normalized();
             v.world_from_view = world_from_view ? *world_from_view : world_from_view_for(v.view);
             v.warp = central_direction_from_string(warp);
             v.source = map_source_from_string(source);
             v.material = std::move(material);
             v.confidence = to_mat(confidence, 1, "confidence");
             v.clipped = to_mat(clipped, 1, "clipped");
             v.attributes = std::move(attributes);
             v.albedo = std::move(albedo);
             return v;
           }),
           py::arg("rgb"), py::arg("view"), py::arg("world_from_view") = py::none(), py::arg("warp") = "mirror",
           py::arg("source") = "computed", py::arg("material") = "", py::arg("confidence") = py::none(),
           py::arg("clipped") = py::none(), py::arg("attributes") = std::map<std::string, std::string>{},
           py::arg("albedo") = std::vector<float>{},
           "MapView(rgb, view, world_from_view=None, warp='mirror', source='computed', material='', confidence=None, "
           "clipped=None, attributes={}, albedo=[]): rgb a float32 (H, W, 3) array (shared, not copied, when float32 "
           "and C-contiguous); view the unit view direction (world, toward the viewer); world_from_view the view "
           "frame (default world_from_view_for(view)). MapSet.validate() checks the invariants.")
      .def_readwrite("view", &MapView::view, "View direction (world, unit, toward the viewer).")
      .def_readwrite("world_from_view", &MapView::world_from_view,
                     "3x3 view frame: columns x right, y up, z = view, in world (the paper's T).")
      .def_property(
          "warp", [](const MapView& v) { return std::string(to_string(v.warp)); },
          [](MapView& v, const std::string& name) { v.warp = central_direction_from_string(name); },
          "'mirror' or 'normal': the central direction the runtime warps.")
      .def_property(
          "source", [](const MapView& v) { return std::string(to_string(v.source)); },
          [](MapView& v, const std::string& name) { v.source = map_source_from_string(name); },
          "'computed' or 'captured'.")
      .def_readwrite("material", &MapView::material, "The BRDF spec as YAML text.")
      .def_readwrite("image", &MapView::image,
                     "The photo view a captured map was extracted from (its name in the photo set); '' when none.")
      .def_readwrite("albedo", &MapView::albedo,
                     "Empty, or the albedo table of albedo-normalised maps: N rows of (r, g, b) at cos = (k+0.5)/N, "
                     "flattened (a list copy).")
      .def_readwrite("attributes", &MapView::attributes, "Provenance strings, written as rsibr.<key> (a dict copy).")
      .def_property(
          "rgb", [](const MapView& v) { return to_array(v.rgb); },
          [](MapView& v, const py::object& a) { v.rgb = to_mat(a, 3, "rgb"); },
          "(H, W, 3) float32 RGB sphere map sharing the view's memory.")
      .def_property(
          "confidence", [](const MapView& v) { return to_array(v.confidence); },
          [](MapView& v, const py::object& a) { v.confidence = to_mat(a, 1, "confidence"); },
          "None, or (H, W) float32 confidence in [0, 1] (captured maps).")
      .def_property(
          "clipped", [](const MapView& v) { return to_array(v.clipped); },
          [](MapView& v, const py::object& a) { v.clipped = to_mat(a, 1, "clipped"); },
          "None, or (H, W) float32: where samples were clipped in every bracket, the confidence the texel would "
          "have had; 0 elsewhere.")
      .def("__repr__", [](const MapView& v) {
        return "MapView(" + std::to_string(v.rgb.cols) + " x " + std::to_string(v.rgb.rows) + ", view (" +
               std::to_string(v.view.x()) + ", " + std::to_string(v.view.y()) + ", " + std::to_string(v.view.z()) +
               "), " + to_string(v.warp) + ", " + to_string(v.source) + ")";
      });

  py::class_<MapSet>(m, "MapSet", "Radiance environment maps, one MapView per view; a sequence of MapViews.")
      .def(py::init([](std::vector<MapView> views) {
             MapSet s;
             s.views = std::move(views);
             return s;
           }),
           py::arg("views") = std::vector<MapView>{},
           "MapSet(views=[]): the views are copied (their pixels are shared).")
      .def("__len__", [](const MapSet& s) { return s.views.size(); })
      .def(
          "__getitem__",
          [](MapSet& s, long i) -> MapView& {
            const long n = long(s.views.size());
            if (i < 0) i += n;
            if (i < 0 || i >= n) throw py::index_error("map set index out of range");
            return s.views[std::size_t(i)];
          },
          py::return_value_policy::reference_internal, "The view at an index (a reference: changes stay in the set).")
      .def(
          "__iter__", [](MapSet& s) { return py::make_iterator(s.views.begin(), s.views.end()); },
          py::keep_alive<0, 1>())
      .def(
          "append", [](MapSet& s, const MapView& v) { s.views.push_back(v); }, py::arg("view"),
          "Appends a copy of a view.")
      .def_property_readonly("width", &MapSet::width, "Width of the maps (0 when empty).")
      .def_property_readonly("height", &MapSet::height, "Height of the maps (0 when empty).")
      .def("view_set", &MapSet::view_set, "The triangulated ViewSet of the views' directions.")
      .def("validate", &validate,
           "Checks the invariants (non-empty, equal sizes, unit views, rotation frames whose third column is the "
           "view, known warp and source); ValueError naming the view and the problem.")
      .def("__repr__", [](const MapSet& s) {
        return "MapSet(" + std::to_string(s.views.size()) + " views, " + std::to_string(s.width()) + " x " +
               std::to_string(s.height()) + ")";
      });

  m.def(
      "read_map_set",
      [](const std::string& path, bool sanitize) {
        check_input_file(path);
        py::gil_scoped_release release;
        return read_map_set(path, sanitize ? BadTexels::zero : BadTexels::refuse);
      },
      py::arg("path"), py::arg("sanitize") = false,
      "Reads a map set (a multi-part OpenEXR file, part view.NNN per view). NaN, Inf and absurd values, or "
      "confidences outside [0, 1], are a RuntimeError naming the file, the counts and the first texel unless "
      "sanitize=True (colours zeroed, confidences clamped). FileNotFoundError for a missing file.");
  m.def(
      "write_map_set",
      [](const std::string& path, const MapSet& set) {
        py::gil_scoped_release release;
        write_map_set(path, set);
      },
      py::arg("path"), py::arg("map_set"),
      "Writes a map set atomically (temporary name, then rename). RuntimeError naming the file on failure.");
  m.def("is_map_set_file", &is_map_set_file, py::arg("path"),
        "True when the file is a multi-part EXR whose first part is view.000.");
}

}  // namespace rsibr::python
