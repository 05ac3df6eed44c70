// cv::Mat <-> numpy for the Python module. Contract (float32 images, RGB order as rsibr keeps them):
//   to_array(mat)  -> a numpy array of shape (rows, cols) or (rows, cols, channels) that SHARES the
//                     Mat's pixels (no copy): it holds a reference to the Mat's buffer, so it stays
//                     valid after the C++ owner is gone, and writes through it are seen by C++.
//   to_mat(array)  -> a cv::Mat header over the array's pixels (no copy) that holds a reference to
//                     the array, so C++ may keep it. A copy is made only when the array is not
//                     float32 or not C-contiguous (numpy's forcecast), e.g. a slice or float64 input.
// Empty Mats map to None and None to an empty Mat.
#pragma once

#include <opencv2/core.hpp>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <string>

namespace rsibr::python {

namespace py = pybind11;

py::object to_array(const cv::Mat& mat);

// `channels`: the channel count the array must have (3: shape (H, W, 3); 1: shape (H, W) or
// (H, W, 1); 0: any of 1..4). `what` names the argument in the ValueError for a wrong shape.
cv::Mat to_mat(const py::handle& array, int channels, const std::string& what);

}  // namespace rsibr::python
