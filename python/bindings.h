// The Python module's parts: one registration function per concept (python/<concept>_binding.cpp),
// called in this order by python/module.cpp (later parts use the types of earlier ones).
#pragma once

#include <pybind11/pybind11.h>

#include <string>

namespace rsibr::python {

namespace py = pybind11;

void bind_layout(py::module_& m);       // LayoutKind, Layout, world_from_view_for, the sphere_map submodule
void bind_view_set(py::module_& m);     // ViewSet, ViewWeights, triangle_weights
void bind_environment(py::module_& m);  // Environment, read_environment, write_environment
void bind_map_set(py::module_& m);      // MapView, MapSet, read_map_set, write_map_set
void bind_bake(py::module_& m);         // Brdf, parse_brdf, load_brdf, bake
void bind_blend(py::module_& m);        // BlendResult, blend
void bind_compare(py::module_& m);      // ErrorMetrics, GainFit, PairComparison, Comparison, compare
void bind_render(py::module_& m);       // Mesh, Camera, look_at, frame_bounds, orbit, Renderer, render
void bind_colour(py::module_& m);       // display_encode

// Inputs are checked as every verb checks them (formats/input_file.h), and the failure becomes the
// matching OSError: FileNotFoundError, IsADirectoryError, or OSError for a FIFO or device; the
// message names the file.
void check_input_file(const std::string& path);

}  // namespace rsibr::python
