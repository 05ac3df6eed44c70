// Meshes (core/mesh.h), cameras (core/camera.h) and rendering with map sets (runtime/renderer.h).
#include "python/bindings.h"
#include "python/numpy_mat.h"

#include "core/camera.h"
#include "core/env_map.h"
#include "formats/map_set.h"
#include "core/mesh.h"
#include "runtime/renderer.h"

#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include <memory>
#include <optional>

namespace rsibr::python {
namespace {

// The renderer with copies of what it refers to (a mesh's arrays, the map sets' view headers: the
// pixels are shared), so Python may drop or change its own objects while it lives.
struct OwningRenderer {
  Mesh mesh;
  std::vector<MapSet> sets;
  std::optional<EnvMap> environment;
  std::unique_ptr<Renderer> renderer;
};

std::vector<MapSet> sets_of(const py::object& maps) {
  if (py::isinstance<MapSet>(maps)) return {maps.cast<MapSet>()};
  return maps.cast<std::vector<MapSet>>();
}

std::unique_ptr<OwningRenderer> make_renderer(const Mesh& mesh, const py::object& maps, const std::string& mode,
                                              int spp, const std::string& warp, int map_size, int rings,
                                              double rim_fade, const std::optional<EnvMap>& environment, bool lod) {
  auto r = std::make_unique<OwningRenderer>();
  r->mesh = mesh;
  r->sets = sets_of(maps);
  r->environment = environment;
  RenderOptions options;
  options.mode = render_mode_from_string(mode);
  options.spp = spp;
  options.warp = warp;
  options.map_size = map_size;
  options.rings = rings;
  options.blend.rim_fade = rim_fade;
  options.lod = lod;
  options.environment = r->environment ? &*r->environment : nullptr;
  std::vector<const MapSet*> pointers;
  for (const MapSet& s : r->sets) pointers.push_back(&s);
  py::gil_scoped_release release;
  r->renderer = std::make_unique<Renderer>(r->mesh, pointers, options);
  return r;
}

cv::Mat render_frame(const OwningRenderer& r, const Camera& camera) {
  py::gil_scoped_release release;
  return r.renderer->render(camera);
}

py::array_t<float> rows_of(const float* data, std::size_t rows, std::size_t cols) {
  py::array_t<float> out({py::ssize_t(rows), py::ssize_t(cols)});
  std::copy(data, data + rows * cols, out.mutable_data());
  return out;
}

}  // namespace

void bind_render(py::module_& m) {
  py::class_<Mesh>(m, "Mesh",
                   "An indexed triangle mesh (object space as stored, right-handed, +Y up; triangles counter-clockwise "
                   "from the front; one unit normal per vertex).")
      .def_property_readonly(
          "positions", [](const Mesh& s) { return rows_of(s.positions.data()->data(), s.positions.size(), 3); },
          "(N, 3) float32 vertex positions (a copy).")
      .def_property_readonly(
          "normals", [](const Mesh& s) { return rows_of(s.normals.data()->data(), s.normals.size(), 3); },
          "(N, 3) float32 unit vertex normals (a copy).")
      .def_property_readonly(
          "triangles",
          [](const Mesh& s) {
            py::array_t<std::uint32_t> out({py::ssize_t(s.triangles.size()), py::ssize_t(3)});
            std::copy(s.triangles.data()->data(), s.triangles.data()->data() + 3 * s.triangles.size(),
                      out.mutable_data());
            return out;
          },
          "(M, 3) uint32 vertex indices (a copy).")
      .def_property_readonly(
          "bounds",
          [](const Mesh& s) {
            const auto b = s.bounds();
            return py::make_tuple(Eigen::Vector3d(b.min().cast<double>()), Eigen::Vector3d(b.max().cast<double>()));
          },
          "(min, max) corners of the axis-aligned bounds.")
      .def("__repr__", [](const Mesh& s) {
        return "Mesh(" + std::to_string(s.positions.size()) + " vertices, " + std::to_string(s.triangles.size()) +
               " triangles)";
      });
  m.def(
      "load_mesh",
      [](const std::string& path) {
        check_input_file(path);
        py::gil_scoped_release release;
        return load_mesh(path);
      },
      py::arg("path"),
      "Loads a .obj, .gltf or .glb mesh (glTF node transforms applied, Draco decoded). RuntimeError naming the file "
      "for malformed content; FileNotFoundError for a missing file.");

  py::class_<Camera>(m, "Camera",
                     "A pinhole camera. Camera frame x right, y down, z forward (mrcal/OpenCV); pixel (0, 0) is the "
                     "CENTRE of the top-left pixel.")
      .def(py::init<>(), "A 640 x 360 camera at (0, 0, 3) looking along +z (world_from_cam identity).")
      .def_readwrite("width", &Camera::width)
      .def_readwrite("height", &Camera::height)
      .def_readwrite("fx", &Camera::fx, "Focal length, pixels.")
      .def_readwrite("fy", &Camera::fy, "Focal length, pixels.")
      .def_readwrite("cx", &Camera::cx, "Principal point, pixels.")
      .def_readwrite("cy", &Camera::cy, "Principal point, pixels.")
      .def_readwrite("eye", &Camera::eye, "Camera centre, world.")
      .def_readwrite("world_from_cam", &Camera::world_from_cam,
                     "Columns: camera x (right), y (down), z (forward) in world.")
      .def("ray_direction", &Camera::ray_direction, py::arg("px"), py::arg("py"),
           "Unit world ray through an image point.")
      .def_property_readonly("forward", &Camera::forward)
      .def_property_readonly("view_direction", &Camera::view_direction, "-forward: the paper mode's view direction.")
      .def_property_readonly("up", &Camera::up, "-y of the camera frame, world.")
      .def(
          "project",
          [](const Camera& c, const Vec3& p) -> std::optional<Vec2> {
            Vec2 px;
            if (!c.project(p, &px)) return std::nullopt;
            return px;
          },
          py::arg("point"), "Image point of a world point; None when it is not in front of the camera.");
  m.def("look_at", &look_at, py::arg("eye"), py::arg("at"), py::arg("up"), py::arg("vfov_deg"), py::arg("width"),
        py::arg("height"),
        "A Camera at eye looking at `at`, `up` toward the image's top, vertical field of view vfov_deg degrees.");
  m.def(
      "frame_bounds",
      [](const Mesh& mesh, const Vec3& direction, const Vec3& up, double vfov, int width, int height, double fill) {
        return frame_bounds(mesh.bounds(), direction, up, vfov, width, height, fill);
      },
      py::arg("mesh"), py::arg("direction"), py::arg("up") = Vec3(0, 1, 0), py::arg("vfov_deg") = 30.0,
      py::arg("width") = 640, py::arg("height") = 360, py::arg("fill") = 0.9,
      "A Camera looking along `direction` (from the camera toward the object) at the mesh's bounds' centre, far "
      "enough that the bounding sphere fills `fill` of the smaller image dimension.");
  m.def("orbit", &orbit, py::arg("camera"), py::arg("pivot"), py::arg("axis"), py::arg("k"), py::arg("n"),
        "Frame k of n of a turntable: the camera rotated about the axis through pivot by 2 pi k / n.");

  py::class_<OwningRenderer>(
      m, "Renderer", "Renders a mesh with one or more map sets (summed, each with its own warps) from any camera.")
      .def(py::init(&make_renderer), py::arg("mesh"), py::arg("maps"), py::arg("mode") = "per-pixel",
           py::arg("spp") = 1, py::arg("warp") = "precomputed", py::arg("map_size") = 0, py::arg("rings") = 16,
           py::arg("rim_fade") = 0.4, py::arg("environment") = py::none(), py::arg("lod") = false,
           "Renderer(mesh, maps, mode='per-pixel', spp=1, warp='precomputed', map_size=0, rings=16, rim_fade=0.4, "
           "environment=None, lod=False): maps a MapSet or a list of them. mode 'per-pixel' (exact) or 'paper' (one "
           "destination map per frame, map_size and warp). spp a perfect square. environment is shown where rays "
           "miss. lod: each pixel reads the maps at its level of detail (ray differentials; `rsibr render --lod`). "
           "Builds "
           "the ray scene and lookups once; the mesh and the views are copied (pixels shared).")
      .def(
          "render", [](const OwningRenderer& r, const Camera& c) { return to_array(render_frame(r, c)); },
          py::arg("camera"),
          "One frame: (H, W, 4) float32 RGBA, scene-linear, alpha-premultiplied; misses black with alpha 0 unless "
          "an environment was given. Releases the GIL.");
  m.def(
      "render",
      [](const Mesh& mesh, const py::object& maps, const Camera& camera, const std::string& mode, int spp,
         const std::string& warp, int map_size, int rings, double rim_fade, const std::optional<EnvMap>& environment,
         bool lod) {
        const auto r = make_renderer(mesh, maps, mode, spp, warp, map_size, rings, rim_fade, environment, lod);
        return to_array(render_frame(*r, camera));
      },
      py::arg("mesh"), py::arg("maps"), py::arg("camera"), py::arg("mode") = "per-pixel", py::arg("spp") = 1,
      py::arg("warp") = "precomputed", py::arg("map_size") = 0, py::arg("rings") = 16, py::arg("rim_fade") = 0.4,
      py::arg("environment") = py::none(), py::arg("lod") = false,
      "One frame of Renderer(mesh, maps, ...).render(camera), as `rsibr render` draws it: (H, W, 4) float32 RGBA.");
}

}  // namespace rsibr::python
