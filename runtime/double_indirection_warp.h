// The warp by double indirection (texture-map double indirection, the textured-sphere patent of
// the project's sources): a screen table and a parametric table, with a rotation about one axis
// applied as an offset into them instead of per-texel arithmetic.
//
// Frames: B is the axis frame (rows e1, e2, a; a = options.axis, a unit vector in view-frame
// coordinates). A direction d of the view frame has the axis-frame address
//   lon = atan2((B d)_y, (B d)_x) in [0, 2 pi),  lat = acos((B d)_z) in [0, pi].
// Screen table (per destination texel, once per size and kind): the address of its central
// direction g(p_d).
// Per source: M' = B M B^T with M = source_from_dest, split into twist and swing,
//   M' = S Rz(delta),  delta = 2 atan2(q_z, q_w) of M''s quaternion (the twist about a),
// so the twist is the offset lon + delta on the screen address. Parametric table (per node of a
// lon x lat grid, `longitudes` columns wrapping round, `latitudes` rows from pole to pole): the
// source disc point and rim value of that node's direction, warp_direction(B^T S dir(lon, lat)).
// For views related by a rotation about a (a ring or turntable whose views all see the axis the same
// way, e.g. world up from a horizontal ring) S = I and the one table built at construction serves
// every source and frame: a frame costs the offset, one bilinear read of the table and no
// trigonometry. Otherwise the swing's table is built per frame and source (nodes warped exactly,
// cached like the tessellated warp's vertices).
//
// Contracts: at a node the result is the exact warp of the node's direction (float32 rounding); in
// between it is bilinear in (lon, lat). A cell whose corners spread more than max_spread in source
// disc units, or (mirror warp) whose rim value drops below min_rim at a corner (the cell straddles
// the source's singularity, where the source coordinates jump across its rim), is warped per texel
// exactly, as the tessellated warp does; interpolated points are kept inside the disc. Error against ExactWarp
// and time: tests/runtime/double_indirection_warp_test.cpp, bench/warp_methods.py.
#pragma once

#include "runtime/warp.h"

#include <memory>
#include <mutex>
#include <utility>
#include <vector>

namespace rsibr {

struct DoubleIndirectionOptions {
  Vec3 axis = Vec3(0, 1, 0);  // the rotation axis in view-frame coordinates (normalised on use)
  int longitudes = 0;         // table columns; 0 = the destination width
  int latitudes = 0;          // table rows, poles included; 0 = half the destination width + 1
  double max_spread = 0.05;   // source disc units (the disc has radius 1)
  double min_rim = 0.05;      // mirror warp only
};

class DoubleIndirectionWarp final : public Warp {
 public:
  // Throws std::invalid_argument for a size < 1, a zero or non-finite axis, or a table of fewer than
  // 3 columns or 3 rows or more than 2^24 nodes.
  DoubleIndirectionWarp(int width, int height, const DoubleIndirectionOptions& options = {});
  const char* name() const override { return "double-indirection"; }
  bool supports(int width, int height) const override { return width == width_ && height == height_; }
  void warp_row(CentralDirection kind, const Mat3& source_from_dest, int width, int height, int row, int c_begin,
                int c_end, WarpSample* out) const override;

  int longitudes() const { return lon_; }
  int latitudes() const { return lat_; }
  // The second indirection alone: the sample at axis-frame address (lon, lat) (radians) for a source
  // related by source_from_dest, i.e. the table read at (lon + delta, lat).
  WarpSample lookup(CentralDirection kind, const Mat3& source_from_dest, double lon, double lat) const;
  // The axis-frame address (lon in [0, 2 pi), lat in [0, pi]) of a view-frame direction (length > 0)
  // and the unit view-frame direction of an address.
  std::pair<double, double> address(const Vec3& dir) const;
  Vec3 direction(double lon, double lat) const;
  // The twist delta of source_from_dest about the axis (radians): the offset on the address.
  double twist(const Mat3& source_from_dest) const;
  // Whether source_from_dest is a rotation about the axis (within 1e-9): the shared table serves it.
  bool offset_only(const Mat3& source_from_dest) const;
  // Cells warped per texel (straddling the singularity) for this kind and rotation.
  int exact_cells(CentralDirection kind, const Mat3& source_from_dest) const;
  // Swing tables built so far (frames that were not a rotation about the axis).
  int tables_built() const;

 private:
  struct Node {
    float x, y, rim;
  };
  struct Table {
    CentralDirection kind;
    Mat3 swing;
    std::vector<Node> nodes;          // row-major, latitudes x longitudes
    std::vector<unsigned char> safe;  // per cell (latitudes - 1) x longitudes
    int exact_cells = 0;
  };
  struct Split {
    double offset;  // the twist, in table columns
    Mat3 swing;
    bool twist_only;
  };
  Split split(const Mat3& source_from_dest) const;
  std::shared_ptr<const Table> build(CentralDirection kind, const Mat3& swing) const;
  std::shared_ptr<const Table> table(CentralDirection kind, const Split& s) const;
  // The bilinear read of a table (nodes, per-cell safe flags, columns x rows) at u (columns, in
  // [0, 2 columns)) and v (rows, in [0, rows - 1]); false (and o untouched) when the cell is not safe.
  static bool interpolate(const Node* nodes, const unsigned char* safe, int columns, int rows, float u, float v,
                          WarpSample& o);
  float wrapped(double u) const;

  int width_, height_, lon_, lat_;
  DoubleIndirectionOptions options_;
  Mat3 axis_from_view_;                   // B
  std::vector<float> screen_[2];          // per kind: (u, v) in table units per destination texel, row-major
  std::vector<Vec3> node_dirs_;           // B^T n(lon_i, lat_j): each node's direction in the view frame
  std::shared_ptr<const Table> base_[2];  // S = I, per kind

  mutable std::mutex mutex_;
  mutable std::vector<std::shared_ptr<const Table>> cache_;  // recent swing tables, newest last
  mutable int built_ = 0;
};

}  // namespace rsibr
