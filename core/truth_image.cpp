#include "core/truth_image.h"

#include "core/atomic_file.h"
#include "core/exr_io.h"
#include "core/text.h"

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfMatrixAttribute.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfStandardAttributes.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <OpenEXR/ImfVecAttribute.h>

#include <stdexcept>

namespace rsibr {

void write_truth_image(const std::filesystem::path& path, const cv::Mat& image, const CameraPose* pose,
                       const std::map<std::string, std::string>& attributes) {
  const int ch = image.channels();
  if (image.depth() != CV_32F || (ch != 1 && ch != 3))
    throw std::runtime_error(path.string() + ": truth images are float RGB or Y");
  const cv::Mat px = image.isContinuous() ? image : image.clone();
  Imf::Header header(px.cols, px.rows);
  header.compression() = Imf::ZIP_COMPRESSION;
  Imf::addChromaticities(header, Imf::Chromaticities());
  for (const auto& [k, v] : attributes) header.insert("rsibr." + k, Imf::StringAttribute(valid_utf8(v)));
  if (pose) {
    Imath::M33f m;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) m[r][c] = float(pose->world_from_cam(r, c));
    header.insert("rsibr.worldFromCam", Imf::M33fAttribute(m));
    header.insert("rsibr.eye", Imf::V3fAttribute(Imath::V3f(float(pose->eye.x()), float(pose->eye.y()),
                                                            float(pose->eye.z()))));
  }
  const char* names[3] = {"R", "G", "B"};
  Imf::FrameBuffer fb;
  char* base = const_cast<char*>(reinterpret_cast<const char*>(px.data));
  const std::size_t stride = sizeof(float) * std::size_t(ch);
  for (int k = 0; k < ch; ++k) {
    const char* name = ch == 1 ? "Y" : names[k];
    header.channels().insert(name, Imf::Channel(Imf::FLOAT));
    fb.insert(name, Imf::Slice(Imf::FLOAT, base + k * sizeof(float), stride, stride * std::size_t(px.cols)));
  }
  try {
    write_atomically(path, [&](const std::string& tmp) {
      Imf::OutputFile out(tmp.c_str(), header);
      out.setFrameBuffer(fb);
      out.writePixels(px.rows);
    });
  } catch (const std::exception& e) {
    throw std::runtime_error(path.string() + ": " + e.what());
  }
}

cv::Mat read_truth_image(const std::filesystem::path& path) {
  try {
    check_exr_before_reading(path.string());
    Imf::InputFile in(path.c_str());
    const Imath::Box2i dw = in.header().dataWindow();
    const auto [w, h] = checked_data_window(dw, path.string());
    const bool grey = in.header().channels().findChannel("Y") != nullptr;
    const int ch = grey ? 1 : 3;
    cv::Mat out(h, w, CV_32FC(ch));
    Imf::FrameBuffer fb;
    const char* names[3] = {"R", "G", "B"};
    const std::size_t stride = sizeof(float) * std::size_t(ch);
    char* base = reinterpret_cast<char*>(out.data) - (std::ptrdiff_t(dw.min.x) + std::ptrdiff_t(dw.min.y) * w) * std::ptrdiff_t(stride);
    for (int k = 0; k < ch; ++k)
      fb.insert(grey ? "Y" : names[k], Imf::Slice(Imf::FLOAT, base + k * sizeof(float), stride, stride * std::size_t(w)));
    in.setFrameBuffer(fb);
    in.readPixels(dw.min.y, dw.max.y);
    return out;
  } catch (const std::exception& e) {
    throw std::runtime_error(path.string() + ": " + e.what());
  }
}

}  // namespace rsibr
