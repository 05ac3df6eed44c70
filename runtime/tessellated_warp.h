// The paper's fast approximation of the warp (the "tessellated disk" of the paper and its patent):
// warp only the vertices of a mesh over the destination disc and interpolate the source texture
// coordinates in between, as texture-mapping hardware would.
//
// Mesh: a polar grid of `rings` rings and `segments` segments. Ring k has disc radius
//   rho_k = sin(pi/2 * k / rings),
// so rings crowd toward the rim, where the warp bends fastest. Each destination texel is bilinear
// in (ring parameter t = asin(rho) * 2 rings / pi, angle * segments / 2 pi) over its cell's four
// vertices; the weights are tabulated once per destination size. Bilinear interpolation on the
// grid is continuous, so there is no seam between cells.
//
// Per frame and source the (rings * segments + 1) vertices are warped exactly (ExactWarp's
// arithmetic) and cached. A cell whose four source points spread more than `max_spread` in source
// disc units, or whose source rim value drops below `min_rim` at a corner (the cell straddles the
// source's singularity, where the source's texture coordinates jump across its rim and interpolating
// them would land in the wrong place), is warped per texel exactly instead. The rim value (the
// singularity fade's input) is interpolated like the coordinates.
//
// Error against ExactWarp: measured by tests/runtime/tessellated_warp_test.cpp and in
// docs/tradeoffs.md, "Warp methods"; it falls as rings * segments grows.
#pragma once

#include "runtime/warp.h"

#include <array>
#include <memory>
#include <mutex>
#include <shared_mutex>
#include <vector>

namespace rsibr {

struct TessellationOptions {
  int rings = 16;
  int segments = 64;
  double max_spread = 0.25;  // source disc units (the disc has radius 1)
  double min_rim = 0.05;
};

class TessellatedWarp final : public Warp {
 public:
  TessellatedWarp(int width, int height, const TessellationOptions& options = {});
  const char* name() const override { return "tessellated"; }
  bool supports(int width, int height) const override { return width == width_ && height == height_; }
  void warp_row(CentralDirection kind, const Mat3& source_from_dest, int width, int height, int row, int c_begin,
                int c_end, WarpSample* out) const override;

  int vertex_count() const { return int(vertices_.size()); }
  // Cells warped per texel (singular) in the last frame computed for this kind and rotation.
  int exact_cells(CentralDirection kind, const Mat3& source_from_dest) const;

 private:
  struct Corners {
    std::array<int, 4> v;    // vertex indices: (k,j), (k+1,j), (k,j+1), (k+1,j+1)
    std::array<float, 4> w;  // bilinear weights
    int cell;                // cell index for the safety flag
  };
  struct Frame {
    CentralDirection kind;
    Mat3 source_from_dest;
    std::vector<WarpSample> samples;  // per vertex
    std::vector<unsigned char> safe;  // per cell
    int exact_cells = 0;
  };
  std::shared_ptr<const Frame> frame(CentralDirection kind, const Mat3& source_from_dest) const;

  int width_, height_;
  TessellationOptions options_;
  std::vector<Vec2> vertices_;   // destination disc coordinates
  std::vector<Corners> texels_;  // row-major width_ * height_ (unused outside the disc)
  int cells_ = 0;
  std::vector<std::array<int, 4>> cell_vertices_;

  // A few recent frames (three sources per blend, mirror and normal kinds), newest last.
  mutable std::shared_mutex mutex_;  // readers share it: a frame is looked up once per row
  mutable std::vector<std::shared_ptr<const Frame>> cache_;
};

}  // namespace rsibr
