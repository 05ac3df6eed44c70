// A map set on the GPU for the viewer's mesh pass (runtime/map_shader.h): every view's map
// in one RGBA32F texture array (RGB, A = confidence, 1 without one or when confidence is off), the
// view frames and warps, the view-set triangulation (core/view_set.h), its edge planes and, for a
// set that does not surround the sphere, the boundary arcs of the covered region. Also the
// CPU engine of paper mode: one destination map per frame (runtime/blend_engine.h) with the chosen
// warp.
#pragma once

#include "formats/map_set.h"
#include "core/view_set.h"
#include "runtime/blend.h"
#include "runtime/blend_engine.h"
#include "runtime/warp.h"

#include <epoxy/gl.h>

#include <memory>
#include <string>

namespace rsibr::viewer {

class GlMapSet {
 public:
  // Keeps a reference to maps. blend: rim_fade, use_confidence, barycentric (the GPU path supports
  // the gnomonic weights only: std::invalid_argument otherwise). warp: a name of make_warp
  // (runtime/make_warp.h; tessellated with `rings` rings, double-indirection about world up) for
  // paper mode's destination map of map_size^2 (0: the set's width).
  GlMapSet(const MapSet& maps, const BlendOptions& blend, const std::string& warp = "precomputed", int map_size = 0,
           int rings = 16);
  ~GlMapSet();
  GlMapSet(const GlMapSet&) = delete;
  GlMapSet& operator=(const GlMapSet&) = delete;

  const MapSet& maps() const { return maps_; }
  const ViewSet& view_set() const { return view_set_; }
  const BlendOptions& blend_options() const { return blend_; }
  // The singularity fade's width (a uniform of the shader, part of the CPU engine's rule: a new
  // engine, whose sources are laid out again as paper mode uses them).
  void set_rim_fade(double rim_fade);
  const std::string& warp_name() const { return warp_name_; }
  int map_size() const { return map_size_; }

  // Paper mode: blends the destination map for (view, up) on the CPU and uploads it (RGB, A = weight).
  // Returns the blend (its rgb/weight/located; kept until the next call).
  const BlendResult& update_destination(const Vec3& view, const Vec3& up);
  const BlendResult& destination() const { return destination_; }
  double last_blend_seconds() const { return blend_seconds_; }

  // Binds the textures to units 0..5 (maps, view data, triangles, edge planes, destination, arcs).
  void bind_textures() const;
  GLuint destination_texture() const { return textures_[4]; }
  int triangle_count() const { return int(view_set_.triangles().size()); }
  int arc_count() const { return arc_count_; }  // boundary arcs (0 when the set surrounds)

 private:
  const MapSet& maps_;
  ViewSet view_set_;
  BlendOptions blend_;
  std::string warp_name_;
  int map_size_;
  std::unique_ptr<Warp> warp_;
  std::unique_ptr<BlendEngine> engine_;
  BlendResult destination_;
  double blend_seconds_ = 0;
  int arc_count_ = 0;
  GLuint textures_[6] = {0, 0, 0, 0, 0, 0};
};

}  // namespace rsibr::viewer
