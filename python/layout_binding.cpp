// Layouts (core/layout.h), the sphere-map coordinates (core/sphere_map.h) and view frames (core/vec.h).
#include "python/bindings.h"
#include "python/numpy_mat.h"

#include "core/env_map.h"
#include "core/layout.h"
#include "core/sphere_map.h"
#include "core/vec.h"

#include <pybind11/eigen.h>
#include <pybind11/operators.h>
#include <pybind11/stl.h>

namespace rsibr::python {
namespace {

// Per-texel values of a width x height map as an (H, W, 3) float64 array and an (H, W) bool mask.
template <class F>
py::tuple texel_field(int width, int height, F&& value) {
  if (width < 1 || height < 1) throw py::value_error("width and height must be positive");
  py::array_t<double> out({py::ssize_t(height), py::ssize_t(width), py::ssize_t(3)});
  py::array_t<bool> mask({py::ssize_t(height), py::ssize_t(width)});
  auto o = out.mutable_unchecked<3>();
  auto k = mask.mutable_unchecked<2>();
  for (int r = 0; r < height; ++r)
    for (int c = 0; c < width; ++c) {
      Vec3 v = Vec3::Zero();
      k(r, c) = value(c, r, v);
      for (int i = 0; i < 3; ++i) o(r, c, i) = v[i];
    }
  return py::make_tuple(out, mask);
}

LayoutKind kind_of(const py::object& kind) {
  if (py::isinstance<py::str>(kind)) return parse_layout_kind(kind.cast<std::string>());
  return kind.cast<LayoutKind>();
}

}  // namespace

void bind_layout(py::module_& m) {
  py::enum_<LayoutKind>(m, "LayoutKind", "Environment-map layouts (docs/conventions.md).")
      .value("LatLong", LayoutKind::LatLong, "lat-long, W x H; first and last columns on the seam, rows on the poles")
      .value("Cube", LayoutKind::Cube, "cube faces +X,-X,+Y,-Y,+Z,-Z stacked vertically, W x 6W")
      .value("Octahedral", LayoutKind::Octahedral, "square N x N (N even), +Y at the centre")
      .value("Sphere", LayoutKind::Sphere, "orthographic mirror ball seen from +Z");
  m.def("parse_layout_kind", &parse_layout_kind, py::arg("name"),
        "'latlong', 'cube', 'octahedral' (or 'octa'), 'sphere' (or 'mirrorball') -> LayoutKind; ValueError otherwise.");

  py::class_<Layout>(m, "Layout",
                     "An environment-map layout with exact direction <-> pixel mappings. Pixel positions are "
                     "continuous with integers at texel centres (column, row); directions are world-frame, +Y up.")
      .def(py::init([](const py::object& kind, int width, int height) { return Layout(kind_of(kind), width, height); }),
           py::arg("kind"), py::arg("width"), py::arg("height"),
           "Layout(kind, width, height): kind a LayoutKind or its name; the size is validated for the kind.")
      .def_static(
          "with_size", [](const py::object& kind, int size) { return Layout::with_size(kind_of(kind), size); },
          py::arg("kind"), py::arg("size"),
          "Conventional shape from one size: lat-long size x size/2, cube size x 6*size, octahedral and "
          "sphere size x size.")
      .def_property_readonly("kind", &Layout::kind, "The LayoutKind.")
      .def_property_readonly(
          "name", [](const Layout& l) { return to_string(l.kind()); }, "The kind's name.")
      .def_property_readonly("width", &Layout::width, "Width in texels.")
      .def_property_readonly("height", &Layout::height, "Height in texels.")
      .def_property_readonly("size", &Layout::size, "The one-number size of with_size.")
      .def_property_readonly("texel_count", &Layout::texel_count, "width * height.")
      .def(
          "direction", [](const Layout& l, const Vec2& p) { return l.direction(p); }, py::arg("pixel"),
          "Unit direction of a continuous pixel position (column, row); None outside the sphere layout's disc.")
      .def("texel_direction", &Layout::texel_direction, py::arg("column"), py::arg("row"),
           "A direction representing texel (column, row); None for texels without solid angle.")
      .def("pixel", &Layout::pixel, py::arg("direction"), "Continuous pixel position (column, row) of a direction.")
      .def("texel_solid_angle", &Layout::texel_solid_angle, py::arg("column"), py::arg("row"),
           "Solid angle (sr) of a texel; the texels partition the sphere (sum 4 pi).")
      .def(
          "texel_directions",
          [](const Layout& l) {
            return texel_field(l.width(), l.height(), [&](int c, int r, Vec3& v) {
              const auto d = l.texel_direction(c, r);
              if (d) v = *d;
              return bool(d);
            });
          },
          "(directions, mask): (H, W, 3) float64 texel_direction of every texel (0 where there is none) and "
          "the (H, W) bool mask of texels that have one.")
      .def(
          "solid_angles", [](const Layout& l) { return to_array(texel_solid_angles(l)); },
          "(H, W) float64 texel solid angles (sr).")
      .def(py::self == py::self)
      .def("__repr__", [](const Layout& l) {
        return "Layout('" + to_string(l.kind()) + "', " + std::to_string(l.width()) + ", " +
               std::to_string(l.height()) + ")";
      });

  m.def("world_from_view_for", &world_from_view_for, py::arg("view"), py::arg("up") = Vec3(0, 1, 0),
        "The view frame T of a view direction (world, toward the viewer): columns x right, y up, z = view, "
        "in world; a fixed fallback up when up is parallel to view (always a rotation).");
  m.def("octahedral_direction", &octahedral_direction, py::arg("uv"),
        "Octahedral (u, v) in [-1,1]^2 -> unit direction.");
  m.def("octahedral_uv", &octahedral_uv, py::arg("direction"), "Unit direction -> octahedral (u, v).");

  py::module_ s = m.def_submodule(
      "sphere_map",
      "Sphere-map coordinates, in the view frame (x right, y up, z toward the viewer). (s, t) in [0,1]^2, t up; "
      "disc coordinates x = 2s-1, y = 2t-1 (unit disc = the sphere's silhouette); texel (column c, row r) of a "
      "W x H map has centre s = (c+0.5)/W, t = 1-(r+0.5)/H.");
  s.def("disc_from_st", &sphere_map::disc_from_st, py::arg("st"), "(s, t) -> disc (x, y).");
  s.def("st_from_disc", &sphere_map::st_from_disc, py::arg("xy"), "Disc (x, y) -> (s, t).");
  s.def("disc_from_pixel", &sphere_map::disc_from_pixel, py::arg("pixel"), py::arg("width"), py::arg("height"),
        "Continuous pixel position (column, row; integers at texel centres) -> disc (x, y).");
  s.def("pixel_from_disc", &sphere_map::pixel_from_disc, py::arg("xy"), py::arg("width"), py::arg("height"),
        "Disc (x, y) -> continuous pixel position.");
  s.def("g_normal", &sphere_map::g_normal, py::arg("xy"),
        "Unit normal (x, y, sqrt(1-x^2-y^2)) of a disc point; outside the disc clamped to the rim.");
  s.def("g_mirror", &sphere_map::g_mirror, py::arg("xy"), "Mirror direction of the viewer z about g_normal(xy).");
  s.def("g_normal_inv", &sphere_map::g_normal_inv, py::arg("normal"), "Disc point whose normal is `normal`.");
  s.def("g_mirror_inv", &sphere_map::g_mirror_inv, py::arg("direction"),
        "Disc point whose mirror direction is `direction` (through the half vector; -z maps to (0, -1)).");
  s.def("disc_rect_area", &sphere_map::disc_rect_area, py::arg("x0"), py::arg("x1"), py::arg("y0"), py::arg("y1"),
        "Exact area of [x0,x1] x [y0,y1] intersected with the unit disc.");
  s.def(
      "normals",
      [](int width, int height) {
        return texel_field(width, height, [&](int c, int r, Vec3& v) {
          const Vec2 xy = sphere_map::disc_from_pixel(Vec2(c, r), width, height);
          v = sphere_map::g_normal(xy);
          return xy.squaredNorm() < 1.0;
        });
      },
      py::arg("width"), py::arg("height"),
      "(normals, inside): g_normal at every texel centre of a W x H sphere map, (H, W, 3) float64 in the view "
      "frame, and the (H, W) bool mask of centres inside the disc (outside: the clamped rim normal).");
  s.def(
      "mirror_directions",
      [](int width, int height) {
        return texel_field(width, height, [&](int c, int r, Vec3& v) {
          const Vec2 xy = sphere_map::disc_from_pixel(Vec2(c, r), width, height);
          v = sphere_map::g_mirror(xy);
          return xy.squaredNorm() < 1.0;
        });
      },
      py::arg("width"), py::arg("height"),
      "(directions, inside): g_mirror at every texel centre, as normals() lays them out.");
}

}  // namespace rsibr::python
