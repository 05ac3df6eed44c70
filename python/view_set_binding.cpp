// View sets (core/view_set.h): view directions, their triangulation and barycentric location.
#include "python/bindings.h"

#include "core/view_set.h"

#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

namespace rsibr::python {
namespace {

Barycentric barycentric_of(const std::string& name) {
  if (name == "gnomonic") return Barycentric::Gnomonic;
  if (name == "solid_angle") return Barycentric::SolidAngle;
  throw std::invalid_argument("barycentric must be 'gnomonic' or 'solid_angle', not '" + name + "'");
}

std::vector<Vec3> directions_of(const py::array_t<double, py::array::c_style | py::array::forcecast>& a) {
  if (a.ndim() != 2 || a.shape(1) != 3) throw py::value_error("views: expected an (N, 3) array of directions");
  std::vector<Vec3> out;
  for (py::ssize_t i = 0; i < a.shape(0); ++i) out.emplace_back(a.at(i, 0), a.at(i, 1), a.at(i, 2));
  return out;
}

}  // namespace

void bind_view_set(py::module_& m) {
  py::class_<ViewWeights>(m, "ViewWeights", "Where a direction lies in a view set: its 1-3 views and weights.")
      .def_readonly("count", &ViewWeights::count, "Views used (1..3).")
      .def_property_readonly(
          "views", [](const ViewWeights& w) { return std::vector<int>(w.views.begin(), w.views.begin() + w.count); },
          "Indices of the views used.")
      .def_property_readonly(
          "weights",
          [](const ViewWeights& w) { return std::vector<double>(w.weights.begin(), w.weights.begin() + w.count); },
          "Their barycentric weights (non-negative, sum 1).")
      .def_readonly("triangle", &ViewWeights::triangle, "Triangle index, or -1 (degenerate sets, boundary arcs).")
      .def_readonly("inside", &ViewWeights::inside, "The direction lies in a triangle of the set.")
      .def_readonly("distance", &ViewWeights::distance, "Radians from the direction to the covered region (0 inside).")
      .def("__repr__", [](const ViewWeights& w) {
        std::string s = "ViewWeights(";
        for (int i = 0; i < w.count; ++i)
          s += (i ? ", " : "") + std::to_string(w.views[std::size_t(i)]) + ": " +
               std::to_string(w.weights[std::size_t(i)]);
        return s + (w.inside ? ")" : ", outside)");
      });

  m.def(
      "triangle_weights",
      [](const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c, const std::string& kind) {
        const auto w = triangle_weights(p, a, b, c, barycentric_of(kind));
        return std::vector<double>(w.begin(), w.end());
      },
      py::arg("p"), py::arg("a"), py::arg("b"), py::arg("c"), py::arg("barycentric") = "gnomonic",
      "Weights of unit p in the spherical triangle (a, b, c): 'gnomonic' (central projection, continuous across "
      "edges; the default) or 'solid_angle' (the paper's sub-triangle areas).");

  py::class_<ViewSet>(m, "ViewSet",
                      "Unit view directions (world, toward the viewer) and their triangulation by the convex hull.")
      .def(py::init([](const py::array_t<double, py::array::c_style | py::array::forcecast>& views) {
             return ViewSet(directions_of(views));
           }),
           py::arg("views"),
           "ViewSet(views): an (N, 3) array of directions (normalised). ValueError for empty sets, zero or "
           "non-finite vectors and views closer than 1e-9 rad.")
      .def_static(
          "named", &ViewSet::named, py::arg("name"),
          "'tetra', 'octa', 'icosa', '12', '42', '162', '642', 'fibN' (N >= 4), or a text file of 'x y z' lines.")
      .def_static("icosahedron", &ViewSet::icosahedron, "The 12 icosahedron vertices.")
      .def_static("geodesic", &ViewSet::geodesic, py::arg("k"),
                  "Geodesic subdivision: k = 0..3 give 12, 42, 162, 642 views.")
      .def_static("tetrahedron", &ViewSet::tetrahedron, "The 4 tetrahedron vertices.")
      .def_static("octahedron", &ViewSet::octahedron, "The 6 axis directions.")
      .def_static("fibonacci", &ViewSet::fibonacci, py::arg("n"), "n >= 4 points of the Fibonacci sphere.")
      .def_property_readonly(
          "views",
          [](const ViewSet& s) {
            py::array_t<double> out({py::ssize_t(s.views().size()), py::ssize_t(3)});
            auto o = out.mutable_unchecked<2>();
            for (std::size_t i = 0; i < s.views().size(); ++i)
              for (int k = 0; k < 3; ++k) o(py::ssize_t(i), k) = s.views()[i][k];
            return out;
          },
          "(N, 3) float64 unit views (a copy).")
      .def_property_readonly(
          "triangles",
          [](const ViewSet& s) {
            py::array_t<int> out({py::ssize_t(s.triangles().size()), py::ssize_t(3)});
            auto o = out.mutable_unchecked<2>();
            for (std::size_t i = 0; i < s.triangles().size(); ++i)
              for (int k = 0; k < 3; ++k) o(py::ssize_t(i), k) = s.triangles()[i][std::size_t(k)];
            return out;
          },
          "(M, 3) int view indices of the spherical triangles, counter-clockwise from outside.")
      .def_property_readonly("surrounds", &ViewSet::surrounds, "True when the triangles cover the whole sphere.")
      .def(
          "locate",
          [](const ViewSet& s, const Vec3& dir, const std::string& kind) {
            return s.locate(dir, barycentric_of(kind));
          },
          py::arg("direction"), py::arg("barycentric") = "gnomonic",
          "ViewWeights of a direction (outside a non-surrounding set: of the nearest covered point).")
      .def("nearest_view", &ViewSet::nearest_view, py::arg("direction"), "Index of the nearest view (ties: lowest).")
      .def("__len__", [](const ViewSet& s) { return s.views().size(); })
      .def("__repr__", [](const ViewSet& s) {
        return "ViewSet(" + std::to_string(s.views().size()) + " views, " + std::to_string(s.triangles().size()) +
               " triangles" + (s.surrounds() ? ")" : ", open)");
      });
}

}  // namespace rsibr::python
