#include "python/numpy_mat.h"

#include <stdexcept>

namespace rsibr::python {
namespace {

// An OpenCV allocator whose buffers belong to numpy arrays (the scheme of OpenCV's own Python
// bindings): the Mat's UMatData points at the array's data and holds one reference to the array,
// dropped (with the GIL taken) when the last Mat sharing the buffer goes. New allocations (a Mat
// that is reallocated by create()) go to OpenCV's standard allocator.
class NumpyAllocator : public cv::MatAllocator {
 public:
  cv::UMatData* wrap(PyObject* array, void* data, std::size_t bytes) const {
    auto* u = new cv::UMatData(this);
    u->data = u->origdata = static_cast<uchar*>(data);
    u->size = bytes;
    u->userdata = array;
    Py_INCREF(array);
    return u;
  }
  cv::UMatData* allocate(int dims, const int* sizes, int type, void* data, std::size_t* step, cv::AccessFlag flags,
                         cv::UMatUsageFlags usage) const override {
    return cv::Mat::getStdAllocator()->allocate(dims, sizes, type, data, step, flags, usage);
  }
  bool allocate(cv::UMatData* u, cv::AccessFlag flags, cv::UMatUsageFlags usage) const override {
    return cv::Mat::getStdAllocator()->allocate(u, flags, usage);
  }
  void deallocate(cv::UMatData* u) const override {
    if (!u || u->refcount != 0) return;
    {
      py::gil_scoped_acquire gil;
      Py_XDECREF(static_cast<PyObject*>(u->userdata));
    }
    delete u;
  }
};

NumpyAllocator& numpy_allocator() {
  static NumpyAllocator* allocator = new NumpyAllocator;  // never destroyed: Mats may outlive statics
  return *allocator;
}

}  // namespace

py::object to_array(const cv::Mat& mat) {
  if (mat.empty()) return py::none();
  if (mat.depth() != CV_32F && mat.depth() != CV_64F)
    throw std::logic_error("to_array: only float images are exported");
  auto* owner = new cv::Mat(mat);  // shares the buffer (reference counted)
  py::capsule keep(owner, [](void* p) { delete static_cast<cv::Mat*>(p); });
  const auto rows = py::ssize_t(mat.rows), cols = py::ssize_t(mat.cols), ch = py::ssize_t(mat.channels());
  const auto step = py::ssize_t(mat.step[0]), pixel = py::ssize_t(mat.elemSize()), value = py::ssize_t(mat.elemSize1());
  const py::dtype type = mat.depth() == CV_32F ? py::dtype::of<float>() : py::dtype::of<double>();
  if (ch == 1) return py::array(type, {rows, cols}, {step, pixel}, owner->data, keep);
  return py::array(type, {rows, cols, ch}, {step, pixel, value}, owner->data, keep);
}

cv::Mat to_mat(const py::handle& object, int channels, const std::string& what) {
  if (object.is_none()) return {};
  auto array = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(object);
  if (!array) throw py::value_error(what + ": expected an array of numbers");
  int ch = 0;
  if (array.ndim() == 2)
    ch = 1;
  else if (array.ndim() == 3)
    ch = int(array.shape(2));
  const bool ok = ch >= 1 && ch <= 4 && (channels == 0 || ch == channels) && array.shape(0) > 0 && array.shape(1) > 0;
  if (!ok) {
    std::string shape = "(";
    for (py::ssize_t i = 0; i < array.ndim(); ++i) shape += (i ? ", " : "") + std::to_string(array.shape(i));
    shape += array.ndim() == 1 ? ",)" : ")";
    const std::string want = channels == 3   ? "(height, width, 3)"
                             : channels == 1 ? "(height, width)"
                                             : "(height, width) or (height, width, 1..4)";
    throw py::value_error(what + ": expected a float32 array of shape " + want + ", got shape " + shape);
  }
  if (!array.writeable()) array = py::array_t<float, py::array::c_style>(array.attr("copy")());
  const int rows = int(array.shape(0)), cols = int(array.shape(1));
  void* data = array.mutable_data();
  cv::Mat mat(rows, cols, CV_32FC(ch), data);
  mat.u = numpy_allocator().wrap(array.ptr(), data, std::size_t(array.nbytes()));
  mat.addref();
  mat.allocator = &numpy_allocator();
  return mat;
}

}  // namespace rsibr::python
