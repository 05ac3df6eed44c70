// An environment (or radiance) map: pixels in one layout. Contract: pixels is CV_32FC(n),
// height x width of the layout, channels in RGB(A) order (not OpenCV's BGR), scene-linear
// radiance in the working colour space (linear Rec.709, D65). For an environment,
// texel p holds L_i(w), the radiance arriving at the origin FROM direction w = layout.direction(p).
#pragma once

#include "core/layout.h"

#include <opencv2/core.hpp>

#include <map>
#include <string>
#include <vector>

namespace rsibr {

struct EnvMap {
  Layout layout;
  cv::Mat pixels;
  // Free-form provenance carried to and from EXR headers (rsibr.* string attributes).
  std::map<std::string, std::string> attributes;

  int channels() const { return pixels.channels(); }
  // Allocates zeroed pixels of the given layout.
  static EnvMap zeros(const Layout& layout, int channels = 3);
};

inline constexpr int kMaxChannels = 4;

// Bilinear sample at a direction (world). Continuous over every seam and fold of the layout:
// lat-long and cube never need a neighbour across a seam (their edge texels lie on it); the
// octahedral map wraps through its fold symmetry; the sphere map ignores texels whose centres are
// outside the disc and renormalises. Writes channels() floats to out.
// Within one texel of a sphere map's rim (the cap around -Z, squeezed into a ring a texel wide and
// stretched ~10 degrees radially) the lookup is the containing texel instead, which keeps the
// energy of that cap (bilinear weights renormalised against the rim would not).
void sample_bilinear(const EnvMap& map, const Vec3& dir, float* out);

// The texel whose cell contains the direction (piecewise-constant reconstruction: integrating it
// over the sphere gives exactly sum_p L(p) Omega(p)). Writes channels() floats.
void sample_nearest(const EnvMap& map, const Vec3& dir, float* out);

// Solid-angle-weighted integral over the sphere, per channel: sum_p L(p) * Omega(p).
std::vector<double> integral(const EnvMap& map);

// Texel solid angles as a CV_64FC1 image (cached per layout by callers that need it often).
cv::Mat texel_solid_angles(const Layout& layout);

}  // namespace rsibr
