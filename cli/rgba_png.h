// An RGBA float frame as an 8-bit PNG: straight alpha, the colour un-premultiplied and encoded by the
// OpenColorIO display transform (core/colour.h display_encode, $OCIO honoured) after 2^exposure.
// The same encoding as rsibr render's PNG output, so the viewer's screenshots compare with it.
#pragma once

#include <opencv2/core.hpp>

#include <string>

namespace rsibr::cli {

// rgba: CV_32FC4, premultiplied. Written atomically; errors name the file.
void write_rgba_png(const std::string& path, const cv::Mat& rgba, float exposure, const std::string& display = "",
                    const std::string& view = "");

}  // namespace rsibr::cli
