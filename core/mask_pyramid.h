// A MIP pyramid of a mask whose levels are authored, not filtered: level l holds whatever the author
// says for each of its texels, so a coarse level can say "this texture is the one to use at this
// level of detail" where the average of the finer level would blur that into a mixture. Sampled at
// a fragment's continuous level of detail (trilinear: bilinear within the two nearest levels, linear
// between them), the mask changes smoothly with the fragment's footprint, so a choice between
// textures of different resolution neither jumps nor scintillates as an object moves or shrinks.
//
// Geometry: level l is max(1, W >> l) x max(1, H >> l) texels, down to 1 x 1. Positions are level-0
// pixel coordinates (mrcal/OpenEXR convention: the centre of texel (c, r) is (c, r)); level l's
// texel (c, r) covers level-0 texels [c 2^l, (c + 1) 2^l) x [r 2^l, (r + 1) 2^l) (clipped to the map),
// so its centre is at ((c + 1/2) 2^l - 1/2, (r + 1/2) 2^l - 1/2) where the levels nest.
#pragma once

#include "core/vec.h"

#include <opencv2/core.hpp>

#include <functional>
#include <vector>

namespace rsibr {

class MaskPyramid {
 public:
  // author(level, col, row) -> the mask value of that texel (clamped to [0, 1]; NaN reads 0).
  // Throws std::invalid_argument for a size < 1.
  MaskPyramid(int width, int height, const std::function<float(int level, int col, int row)>& author);

  int levels() const { return int(levels_.size()); }
  const cv::Mat& level(int l) const { return levels_.at(std::size_t(l)); }  // CV_32FC1
  int width() const { return levels_.front().cols; }
  int height() const { return levels_.front().rows; }

  // The level-0 texels level l's texel (c, r) covers (the last texel of a level whose size was
  // rounded down also covers the remainder).
  cv::Rect footprint(int level, int col, int row) const { return footprint(width(), height(), level, col, row); }
  static cv::Rect footprint(int width, int height, int level, int col, int row);

  // Bilinear at a level-0 pixel position within level l (clamp to edge).
  float sample_level(const Vec2& pixel0, int level) const;
  // Trilinear at level of detail lod (clamped to [0, levels() - 1]; NaN reads level 0).
  float sample(const Vec2& pixel0, double lod) const;

 private:
  std::vector<cv::Mat> levels_;
};

}  // namespace rsibr
