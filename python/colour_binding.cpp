// Display encoding for pictures (core/colour.h): the OpenColorIO view transform the PNG previews use.
#include "python/bindings.h"
#include "python/numpy_mat.h"

#include "core/colour.h"

#include <opencv2/imgproc.hpp>

namespace rsibr::python {

void bind_colour(py::module_& m) {
  m.def(
      "display_encode",
      [](const py::object& rgb, float exposure, const std::string& display, const std::string& view) {
        const cv::Mat linear = to_mat(rgb, 0, "rgb");
        if (linear.channels() != 3 && linear.channels() != 4)
          throw py::value_error("display_encode: rgb must have 3 or 4 channels (alpha is ignored)");
        cv::Mat bgr;
        {
          py::gil_scoped_release release;
          cv::cvtColor(display_encode(linear, exposure, display, view), bgr, cv::COLOR_BGR2RGB);
        }
        py::array_t<std::uint8_t> out({py::ssize_t(bgr.rows), py::ssize_t(bgr.cols), py::ssize_t(3)});
        for (int r = 0; r < bgr.rows; ++r)
          std::copy(bgr.ptr<std::uint8_t>(r), bgr.ptr<std::uint8_t>(r) + 3 * bgr.cols, out.mutable_data(r));
        return out;
      },
      py::arg("rgb"), py::arg("exposure") = 0.0f, py::arg("display") = "", py::arg("view") = "",
      "Scene-linear (H, W, 3 or 4) float32 RGB in the working space -> (H, W, 3) uint8 RGB for display: scaled by "
      "2^exposure, through the OpenColorIO display/view transform ($OCIO, else the built-in config; empty names: "
      "its defaults) and quantised, as the PNG previews of the verbs (a new array).");
}

}  // namespace rsibr::python
