// Environments (core/env_map.h) and their files (formats/exr_io.h).
#include "python/bindings.h"
#include "python/numpy_mat.h"

#include "core/cell_centred_latlong.h"
#include "core/env_map.h"
#include "formats/exr_io.h"
#include "core/texel_audit.h"

#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include <optional>

namespace rsibr::python {
namespace {

Layout layout_of(const py::object& layout, const cv::Mat& pixels) {
  if (py::isinstance<Layout>(layout)) return layout.cast<Layout>();
  if (pixels.empty()) throw py::value_error("Environment: a layout name needs pixels to take the size from");
  const LayoutKind kind =
      py::isinstance<py::str>(layout) ? parse_layout_kind(layout.cast<std::string>()) : layout.cast<LayoutKind>();
  return Layout(kind, pixels.cols, pixels.rows);
}

void check_pixels(const EnvMap& e) {
  if (e.pixels.empty()) return;
  if (e.pixels.cols != e.layout.width() || e.pixels.rows != e.layout.height())
    throw py::value_error("Environment: pixels are " + std::to_string(e.pixels.cols) + " x " +
                          std::to_string(e.pixels.rows) + " but the layout is " + std::to_string(e.layout.width()) +
                          " x " + std::to_string(e.layout.height()));
}

std::vector<float> sample(const EnvMap& e, const Vec3& dir, bool nearest) {
  if (e.pixels.empty()) throw py::value_error("Environment: no pixels");
  if (!dir.allFinite() || !(dir.norm() > 0)) throw py::value_error("direction must be a non-zero finite vector");
  std::vector<float> out(std::size_t(e.channels()));
  if (nearest)
    sample_nearest(e, dir, out.data());
  else
    sample_bilinear(e, dir, out.data());
  return out;
}

}  // namespace

void bind_environment(py::module_& m) {
  py::class_<EnvMap>(m, "Environment",
                     "An environment map: pixels in one layout. Texel p holds L_i(w), the radiance arriving at the "
                     "origin FROM direction w = layout.direction(p); scene-linear, linear Rec.709 / D65, RGB(A).")
      .def(
          py::init(
              [](const py::object& pixels, const py::object& layout, std::map<std::string, std::string> attributes) {
                EnvMap e;
                e.pixels = to_mat(pixels, 0, "pixels");
                e.layout = layout_of(layout, e.pixels);
                e.attributes = std::move(attributes);
                check_pixels(e);
                return e;
              }),
          py::arg("pixels"), py::arg("layout") = "latlong",
          py::arg("attributes") = std::map<std::string, std::string>{},
          "Environment(pixels, layout='latlong', attributes={}): pixels a float32 (H, W, C) array, C in 1..4 (shared, "
          "not copied, when float32 and C-contiguous); layout a Layout, or a LayoutKind or name sized from the pixels.")
      .def_static("zeros", &EnvMap::zeros, py::arg("layout"), py::arg("channels") = 3, "Zeroed pixels of a layout.")
      .def_readwrite("layout", &EnvMap::layout, "The Layout.")
      .def_property(
          "pixels", [](const EnvMap& e) { return to_array(e.pixels); },
          [](EnvMap& e, const py::object& a) {
            EnvMap next = e;
            next.pixels = to_mat(a, 0, "pixels");
            check_pixels(next);
            e.pixels = next.pixels;
          },
          "(H, W, C) float32 array sharing the environment's memory (writes are seen by C++). Assigning an array "
          "shares it too (a copy only for other dtypes or non-contiguous arrays); its shape must match the layout.")
      .def_readwrite(
          "attributes", &EnvMap::attributes,
          "Provenance strings written to the EXR header as rsibr.<key> (a dict; assign a new dict to change).")
      .def_property_readonly("channels", &EnvMap::channels, "Channel count.")
      .def("integral", &integral, "Solid-angle-weighted integral over the sphere per channel: sum_p L(p) Omega(p).")
      .def(
          "sample", [](const EnvMap& e, const Vec3& d) { return sample(e, d, false); }, py::arg("direction"),
          "Bilinear sample at a world direction, continuous over every seam (a list of channel values).")
      .def(
          "sample_nearest", [](const EnvMap& e, const Vec3& d) { return sample(e, d, true); }, py::arg("direction"),
          "The texel whose cell contains the direction.")
      .def("__repr__", [](const EnvMap& e) {
        return "Environment(" + to_string(e.layout.kind()) + ", " + std::to_string(e.layout.width()) + " x " +
               std::to_string(e.layout.height()) + ", " + std::to_string(e.pixels.channels()) + " channels)";
      });

  m.def(
      "read_environment",
      [](const std::string& path, const std::optional<std::string>& layout, bool sanitize, bool fold_ringing) {
        check_input_file(path);
        const std::optional<LayoutKind> hint =
            layout ? std::optional<LayoutKind>(parse_layout_kind(*layout)) : std::nullopt;
        EnvReadReport report;
        EnvMap env;
        {
          py::gil_scoped_release release;
          env = read_environment(path, hint, &report);
        }
        if (report.texels.bad() && !sanitize)
          throw std::runtime_error(path + ": " + report.texels.describe() + "; pass sanitize=True to zero them");
        if (sanitize) sanitize_texels(env.pixels);
        // The rule of the command line's environment inputs (formats/exr_io.h).
        if (fold_ringing) {
          const std::string folded = fold_environment_ringing(env, path, report, sanitize);
          if (!folded.empty() && PyErr_WarnEx(PyExc_UserWarning, folded.c_str(), 1) != 0) throw py::error_already_set();
        }
        return env;
      },
      py::arg("path"), py::arg("layout") = py::none(), py::arg("sanitize") = false, py::arg("fold_ringing") = true,
      "Reads an OpenEXR or Radiance .hdr environment. Layout: the file's envmap or rsibr.layout attribute, else "
      "`layout` (a name), else the shape (2:1 lat-long, 1:6 cube). Pixels are converted to the working space. "
      "NaN, Inf and absurd values are a RuntimeError naming the file unless sanitize=True, which zeroes them. "
      "Negative values (lossy-compression ringing) are folded into their positive neighbours, the integral kept, "
      "with a UserWarning giving the count (as the command line does), unless fold_ringing=False. RuntimeError "
      "for unreadable files, FileNotFoundError for missing ones.");
  m.def(
      "write_environment",
      [](const std::string& path, const EnvMap& env, bool half) {
        check_pixels(env);
        ExrWriteOptions options;
        options.half = half;
        py::gil_scoped_release release;
        write_environment(path, env, options);
      },
      py::arg("path"), py::arg("environment"), py::arg("half") = false,
      "Writes an OpenEXR environment atomically (temporary name, then rename), with its layout, Rec.709 "
      "chromaticities and attributes (names under 32 characters). half=True stores half floats (values beyond "
      "65504 are an error). RuntimeError naming the file on failure.");
  m.def(
      "to_cell_centred_latlong",
      [](const EnvMap& env, int width, int height) {
        check_pixels(env);
        if (width < 1 || height < 1) throw py::value_error("to_cell_centred_latlong: width and height must be >= 1");
        py::gil_scoped_release release;
        return to_cell_centred_latlong(env, width, height);
      },
      py::arg("environment"), py::arg("width"), py::arg("height"),
      "The environment's radiance as a width x height lat-long image in the cell-centred convention of Blender, "
      "Cycles and pbrt (texel (i, j) at longitude pi (1 - 2 (i + 1/2) / W), latitude pi/2 - pi (j + 1/2) / H), each "
      "texel the bilinear sample at its direction. For other programs only: rsibr reads lat-long files in "
      "OpenEXR's convention (docs/conventions.md), so this image read back by rsibr is stretched by a texel.");
  m.def(
      "cell_centred_latlong_direction",
      [](double i, double j, int width, int height) { return cell_centred_latlong_direction(i, j, width, height); },
      py::arg("i"), py::arg("j"), py::arg("width"), py::arg("height"),
      "World direction (unit, rsibr's frame) of the cell-centred lat-long texel (i, j) of a width x height image.");
}

}  // namespace rsibr::python
