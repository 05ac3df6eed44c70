#include "core/colour.h"

#include "core/text.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <mutex>
#include <sstream>
#include <stdexcept>

#include <Eigen/LU>
#include <OpenEXR/ImfChromaticities.h>

namespace OCIO = OCIO_NAMESPACE;

namespace rsibr {
namespace detail {
extern const char* const embedded_ocio_config;  // generated from core/data/ocio/config.ocio
}

namespace {

std::mutex g_config_mutex;
OCIO::ConstConfigRcPtr g_config;  // guarded by g_config_mutex

OCIO::ConstConfigRcPtr load_config() {
  const char* env = std::getenv("OCIO");
  if (env != nullptr && env[0] != '\0') {
    try {
      OCIO::ConstConfigRcPtr config = OCIO::Config::CreateFromFile(env);
      config->validate();
      return config;
    } catch (const std::exception& e) {
      throw std::runtime_error("rsibr: cannot load the OpenColorIO config named by $OCIO ('" + std::string(env) +
                               "'): " + one_line(e.what()));
    }
  }
  try {
    std::istringstream text(detail::embedded_ocio_config);
    OCIO::ConstConfigRcPtr config = OCIO::Config::CreateFromStream(text);
    config->validate();
    return config;
  } catch (const std::exception& e) {
    throw std::runtime_error("rsibr: the embedded OpenColorIO config is invalid: " + one_line(e.what()));
  }
}

void require_colour_space(const OCIO::Config& config, const std::string& name) {
  if (name.empty() || !config.getColorSpace(name.c_str())) {
    throw std::runtime_error("rsibr: unknown colour space '" + name + "' in the OpenColorIO config");
  }
}

// Column-vector 3x3 from Imath's row-vector 4x4 (Imath applies v * M).
Eigen::Matrix3d to_column_major_3x3(const Imath::M44f& m) {
  Eigen::Matrix3d out;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) out(r, c) = static_cast<double>(m[c][r]);
  }
  return out;
}

Eigen::Vector3d xyz_of_white(const Imath::V2f& xy) {
  const double x = xy.x;
  const double y = xy.y;
  return {x / y, 1.0, (1.0 - x - y) / y};
}

// Linearised Bradford chromatic adaptation (column vectors) from white `src` to white `dst`.
Eigen::Matrix3d bradford(const Imath::V2f& src, const Imath::V2f& dst) {
  Eigen::Matrix3d b;
  b << 0.8951, 0.2664, -0.1614,  //
      -0.7502, 1.7135, 0.0367,   //
      0.0389, -0.0685, 1.0296;
  const Eigen::Vector3d s = b * xyz_of_white(src);
  const Eigen::Vector3d d = b * xyz_of_white(dst);
  return b.inverse() * d.cwiseQuotient(s).asDiagonal() * b;
}

}  // namespace

OCIO::ConstConfigRcPtr colour_config() {
  std::lock_guard<std::mutex> lock(g_config_mutex);
  if (!g_config) g_config = load_config();
  return g_config;
}

void reset_colour_config_for_testing() {
  std::lock_guard<std::mutex> lock(g_config_mutex);
  g_config.reset();
}

std::string working_space() {
  const OCIO::ConstConfigRcPtr config = colour_config();
  const OCIO::ConstColorSpaceRcPtr cs = config->getColorSpace(OCIO::ROLE_SCENE_LINEAR);
  if (!cs) throw std::runtime_error("rsibr: the OpenColorIO config has no 'scene_linear' role");
  return cs->getName();
}

void convert_colour_space(cv::Mat& rgb, const std::string& from, const std::string& to) {
  const OCIO::ConstConfigRcPtr config = colour_config();
  require_colour_space(*config, from);
  require_colour_space(*config, to);
  if (rgb.type() != CV_32FC3 && rgb.type() != CV_32FC4) {
    throw std::runtime_error("rsibr: convert_colour_space needs a CV_32FC3 or CV_32FC4 image");
  }
  if (rgb.empty()) return;
  // Lossless optimisation: exact pow/log (the default level approximates them).
  const OCIO::ConstCPUProcessorRcPtr cpu =
      config->getProcessor(from.c_str(), to.c_str())->getOptimizedCPUProcessor(OCIO::OPTIMIZATION_LOSSLESS);
  if (cpu->isNoOp()) return;
  const long channels = rgb.channels();
  OCIO::PackedImageDesc desc(rgb.data, rgb.cols, rgb.rows, channels, OCIO::BIT_DEPTH_F32, sizeof(float),
                             static_cast<ptrdiff_t>(sizeof(float) * channels), static_cast<ptrdiff_t>(rgb.step[0]));
  cpu->apply(desc);
}

void apply_display_transform(cv::Mat& rgb, const std::string& display, const std::string& view) {
  if (rgb.type() != CV_32FC3) throw std::runtime_error("rsibr: the display transform needs a CV_32FC3 image");
  const OCIO::ConstConfigRcPtr config = colour_config();
  const std::string disp = display.empty() ? std::string(config->getDefaultDisplay()) : display;
  bool display_known = false;
  for (int i = 0; i < config->getNumDisplays(); ++i) {
    if (disp == config->getDisplay(i)) display_known = true;
  }
  if (!display_known) {
    throw std::runtime_error("rsibr: unknown display '" + disp + "' in the OpenColorIO config");
  }
  const std::string v = view.empty() ? std::string(config->getDefaultView(disp.c_str())) : view;
  bool view_known = false;
  for (int i = 0; i < config->getNumViews(disp.c_str()); ++i) {
    if (v == config->getView(disp.c_str(), i)) view_known = true;
  }
  if (!view_known) {
    throw std::runtime_error("rsibr: unknown view '" + v + "' for display '" + disp + "' in the OpenColorIO config");
  }

  if (!rgb.empty()) {
    const OCIO::ConstCPUProcessorRcPtr cpu =
        config->getProcessor(working_space().c_str(), disp.c_str(), v.c_str(), OCIO::TRANSFORM_DIR_FORWARD)
            ->getDefaultCPUProcessor();
    OCIO::PackedImageDesc desc(rgb.data, rgb.cols, rgb.rows, 3, OCIO::BIT_DEPTH_F32, sizeof(float), 3 * sizeof(float),
                               static_cast<ptrdiff_t>(rgb.step[0]));
    cpu->apply(desc);
  }
}

cv::Mat display_encode(const cv::Mat& linear_rgb, float exposure_stops, const std::string& display,
                       const std::string& view) {
  if (linear_rgb.type() != CV_32FC3 && linear_rgb.type() != CV_32FC4) {
    throw std::runtime_error("rsibr: display_encode needs a CV_32FC3 or CV_32FC4 image");
  }
  // Scale and sanitise: NaN -> 0 and +-Inf -> +-max finite, so the transform sees finite input.
  const float gain = std::exp2(exposure_stops);
  const float big = std::numeric_limits<float>::max();
  cv::Mat work(linear_rgb.size(), CV_32FC3);
  const int in_channels = linear_rgb.channels();
  for (int y = 0; y < linear_rgb.rows; ++y) {
    const float* src = linear_rgb.ptr<float>(y);
    float* dst = work.ptr<float>(y);
    for (int x = 0; x < linear_rgb.cols; ++x) {
      for (int c = 0; c < 3; ++c) {
        const float s = src[x * in_channels + c] * gain;
        dst[x * 3 + c] = std::isnan(s) ? 0.0f : std::clamp(s, -big, big);
      }
    }
  }

  apply_display_transform(work, display, view);

  // Quantise with rounding, clamping, NaN -> 0, and RGB -> BGR.
  cv::Mat out(linear_rgb.size(), CV_8UC3);
  for (int y = 0; y < work.rows; ++y) {
    const float* src = work.ptr<float>(y);
    unsigned char* dst = out.ptr<unsigned char>(y);
    for (int x = 0; x < work.cols; ++x) {
      for (int c = 0; c < 3; ++c) {
        const float e = src[x * 3 + c];
        unsigned char q = 0;
        if (e >= 1.0f) {
          q = 255;
        } else if (e > 0.0f) {  // false for NaN
          q = static_cast<unsigned char>(std::lround(e * 255.0f));
        }
        dst[x * 3 + (2 - c)] = q;
      }
    }
  }
  return out;
}

Eigen::Matrix3d working_from_chromaticities(const Imf::Chromaticities& c) {
  const Imf::Chromaticities working;  // default: Rec.709 primaries, D65 white
  const Eigen::Matrix3d xyz_from_rgb = to_column_major_3x3(Imf::RGBtoXYZ(c, 1.0f));
  // Invert in double rather than using Imf::XYZtoRGB so the Rec.709 case is identity to ~1e-7.
  const Eigen::Matrix3d working_from_xyz = to_column_major_3x3(Imf::RGBtoXYZ(working, 1.0f)).inverse();
  if (c.white == working.white) return working_from_xyz * xyz_from_rgb;
  return working_from_xyz * bradford(c.white, working.white) * xyz_from_rgb;
}

}  // namespace rsibr
