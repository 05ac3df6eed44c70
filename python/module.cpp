// The rsibr Python module: map sets, environments, bake, blend, render and compare on numpy arrays.
// C++ exceptions become Python ones by pybind11's translation: std::invalid_argument (bad values,
// inconsistent inputs) -> ValueError, std::runtime_error (unreadable or invalid files, whose message
// starts with the file's path) -> RuntimeError; missing inputs are OSErrors (python/bindings.h).
#include "python/bindings.h"

#include "formats/file_error.h"
#include "formats/input_file.h"

#include <cerrno>
#include <filesystem>

namespace rsibr::python {

void check_input_file(const std::string& path) {
  try {
    require_regular_file(path);
  } catch (const FileError& e) {
    std::error_code ec;
    const auto status = std::filesystem::status(path, ec);
    PyObject* type = PyExc_OSError;
    int code = EINVAL;
    if (!std::filesystem::exists(status))
      type = PyExc_FileNotFoundError, code = ENOENT;
    else if (std::filesystem::is_directory(status))
      type = PyExc_IsADirectoryError, code = EISDIR;
    PyErr_SetObject(type, py::make_tuple(code, e.what(), path).ptr());
    throw py::error_already_set();
  }
}

}  // namespace rsibr::python

PYBIND11_MODULE(rsibr, m) {
  using namespace rsibr::python;
  m.doc() =
      "rsibr: reflection-space image-based rendering (radiance environment maps, one sphere map per view).\n\n"
      "Images are float32 numpy arrays, RGB order, scene-linear (linear Rec.709, D65): environments (H, W, C), "
      "sphere maps (H, W, 3), confidences (H, W). Arrays returned share memory with the C++ objects; arrays "
      "given are used without a copy when they are float32 and C-contiguous (otherwise converted once).\n"
      "Directions are world-frame 3-vectors (+Y up). Errors: ValueError for bad values or inconsistent inputs, "
      "RuntimeError for unreadable or invalid files (the message starts with the path), FileNotFoundError and "
      "other OSErrors for missing inputs.";
  m.attr("__version__") = RSIBR_VERSION;
  bind_layout(m);
  bind_view_set(m);
  bind_environment(m);
  bind_map_set(m);
  bind_bake(m);
  bind_blend(m);
  bind_compare(m);
  bind_render(m);
  bind_colour(m);
}
