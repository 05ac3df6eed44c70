// Rendering meshes with map sets: every pixel shows the radiance a map set gives
// for the visible surface's normal and the direction to the eye.
//
// Semantics. A map for view v (world, toward the viewer) with frame T = world_from_view holds at
// texel p the radiance leaving a surface with normal n = T g_normal(p) toward a viewer at infinity
// along v (docs/conventions.md). A pixel sample is a primary ray through the camera (core/camera.h, mrcal
// pixel convention: (0,0) is the centre of the top-left pixel) traced against the mesh with Embree
// (core/ray_scene.h, both faces). At a hit, n is the interpolated shading normal, flipped when the
// hit triangle's geometric normal faces away from the eye (meshes are two-sided), and v_px = -ray
// direction is the unit direction to the eye. Then, for each map set (summed over sets):
//
//   Paper mode (RenderMode::Paper, the paper's approximation): once per frame, blend ONE destination
//     map for v = camera.view_direction() (= -forward) with up = camera.up() (runtime/blend.h, with
//     the chosen warp, map_size^2 texels). Each pixel then reads it at the disc point of T_d^T n,
//     bilinearly (runtime/disc_sampler.h). Normals facing away from v (z < 0 in the destination
//     frame, seen at the silhouette in perspective) take the nearest rim point (warp_direction's
//     normal inverse). v_px is ignored: the error grows with the angle between v_px and v, i.e. with
//     the field of view and toward the image's edges. The destination map is a second resampling, so
//     paper mode also blurs by one bilinear pass at map_size.
//   Per-pixel mode (RenderMode::PerPixel, exact): BlendEngine::radiance (runtime/blend_engine.h) for
//     (v_px, n): v_px located in the view set, each located source warped from the pixel's own
//     central direction (mirror r = 2(n.v)n - v, or n), faded, sampled as blend() samples, normalised.
//     No destination map, so no second resampling and no field-of-view error.
//
//   Several map sets (e.g. a normal-lobe and a mirror-lobe set of one BRDF): each is evaluated with
//   its own warps (MapView::warp) and the results are summed.
//
// Output: CV_32FC4, RGBA, scene-linear, alpha-premultiplied (OpenEXR's convention). With spp = k^2
// samples per pixel on a k x k grid of subpixel offsets ((i + 1/2)/k - 1/2, i < k; k = 1 is the pixel
// centre), RGB is the mean over samples and alpha the fraction that hit the mesh. Samples that miss
// are black with alpha 0, or, with an environment, L_i(ray direction) with alpha 1.
// Results do not depend on the thread count or the tile split.
#pragma once

#include "core/camera.h"
#include "core/env_map.h"
#include "formats/map_set.h"
#include "core/mesh.h"
#include "core/ray_scene.h"
#include "runtime/blend.h"

#include <opencv2/core.hpp>

#include <memory>
#include <string>
#include <vector>

namespace rsibr {

enum class RenderMode { Paper, PerPixel };
// "paper" / "per-pixel"; throws std::invalid_argument otherwise.
RenderMode render_mode_from_string(const std::string& name);
const char* to_string(RenderMode mode);

struct RenderOptions {
  // Per-pixel by default: exact (no field-of-view error, no second resampling) at a small cost over
  // paper mode. Why per-pixel: measured in docs/tradeoffs.md, "Measured choices in the code".
  RenderMode mode = RenderMode::PerPixel;
  // Paper mode: the destination map is map_size x map_size (0: the first map set's width), blended
  // with this warp (runtime/make_warp.h: "exact", "precomputed", "tessellated" with `rings` rings and
  // 4 x rings segments, or "double-indirection" about world up (0, 1, 0) as the first map set's views
  // see it). The warp tables are built once and reused for every frame.
  int map_size = 0;
  std::string warp = "precomputed";
  int rings = 16;
  // rim_fade, use_confidence and barycentric are used (width, height, warp, source_weights are not).
  BlendOptions blend;
  // Samples per pixel: a perfect square (1, 4, 9, ...).
  int spp = 1;
  // Per-pixel mode: read each source at the level of detail of the sample's footprint (ray
  // differentials: the normal's change to the neighbouring pixels' hits, the smaller of the forward
  // and backward differences so a silhouette or a depth step does not widen it, divided by the
  // samples per pixel side) through BlendEngine::radiance with a Footprint: MIP levels of the
  // sources and, for mixed-resolution sets, the MIP-mask blend (runtime/blend_engine.h). Off: one
  // bilinear tap per source, however small the object is on screen (aliasing that scintillates
  // when it moves; measured in docs/tradeoffs.md, "MIP-mask blending"). Paper mode reads its
  // destination map the same way, at the footprint's level of its MIP pyramid.
  bool lod = false;
  // Shown where rays miss (alpha 1); nullptr: black with alpha 0. Not owned.
  const EnvMap* environment = nullptr;
};

struct RenderStats {
  long long samples = 0;         // pixel samples (width x height x spp), traced or culled
  long long hits = 0;            // of which hit the mesh
  long long covered_pixels = 0;  // pixels with alpha > 0 from the mesh
  double seconds = 0;            // the whole frame
  double seconds_blend = 0;      // paper mode: the destination maps
};

class Renderer {
 public:
  // Builds the Embree scene and, per map set, its view set and lookups (and the paper mode's warp
  // tables). Keeps references: mesh and the map sets must outlive the renderer. Throws
  // std::invalid_argument for no map set, an invalid set, a bad spp, map size or warp name.
  Renderer(const Mesh& mesh, const std::vector<const MapSet*>& sets, const RenderOptions& options = {});
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  // One frame (camera.width x camera.height). Thread-safe for concurrent calls.
  cv::Mat render(const Camera& camera, RenderStats* stats = nullptr) const;
  // The same into `out`, reusing its buffer when its size and type match (a caller that renders many
  // frames keeps one image: a fresh 15 MB image per 1280x720 frame costs its page faults every frame).
  // Any cv::Mat sharing out's data sees the new frame.
  void render(const Camera& camera, cv::Mat& out, RenderStats* stats = nullptr) const;

  // The primary-ray pass alone (same rays and tiles, no shading): the count of hits. For benchmarks.
  long long trace_only(const Camera& camera) const;

  const RenderOptions& options() const { return options_; }
  const RayScene& scene() const;

 private:
  struct Impl;
  RenderOptions options_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace rsibr
