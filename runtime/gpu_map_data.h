// A map set laid out as the mesh pass's shader reads it (runtime/map_shader.h), without any graphics
// API: the desktop viewer uploads these arrays (runtime/viewer/gl_map_set.h), the page viewer embeds
// them (runtime/web_viewer_page.h). Every array is RGBA texels, rows in order, top row first.
#pragma once

#include "core/view_set.h"
#include "formats/map_set.h"
#include "runtime/blend.h"

#include <vector>

namespace rsibr {

struct GpuMapData {
  int width = 0, height = 0, views = 0;  // the maps: `views` layers of width x height
  // Layer by layer: RGB, A = confidence (1 without one or when the blend does not use it).
  std::vector<float> maps;
  // views x 4 texels: rows 0..2 the rows of view_from_world, row 0's A the warp (0 mirror, 1
  // normal); row 3 the unit view vector of the view set.
  std::vector<float> view_data;
  std::vector<int> triangles;      // triangle_count x 1: the three view indices, 0
  std::vector<float> edge_planes;  // triangle_count x 3: unit a x b, b x c, c x a (locate's margin)
  // max(arc_count, 1) x 1: the boundary arcs of a set that does not surround the sphere (triangle
  // edges no other triangle shares): views a, b, their triangle, 0.
  std::vector<int> arcs;
  int triangle_count = 0, arc_count = 0;
};

// Throws std::invalid_argument ("viewer: ...") for a set the shader cannot draw: fewer than three
// views in a spherical triangle, barycentric weights other than the gnomonic ones, or a source the
// blend refuses (runtime/blend.h).
GpuMapData gpu_map_data(const MapSet& maps, const ViewSet& view_set, const BlendOptions& blend);

}  // namespace rsibr
