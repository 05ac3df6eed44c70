// Map sets: radiance environment maps, one sphere map per view, captured or computed alike
// (docs/conventions.md). On disk: one multi-part OpenEXR file, part "view.NNN" per view, with
//   rsibr.view           V3f   view direction (world, unit, toward the viewer)
//   rsibr.worldFromView  M33f  the paper's T: columns are the view frame's axes in world
//                              (stored as Imath m[row][col] = T(row, col))
//   rsibr.warp           "mirror" | "normal"   which central direction the runtime warps
//   rsibr.source         "computed" | "captured"
//   rsibr.material       the BRDF spec as text
//   rsibr.albedo         optional FloatVector: the maps are albedo-normalised (texels hold L / A(n.v));
//                        A's table as core/albedo_normalisation.h lays it out; the same for every view
//   rsibr.<key>          provenance strings (MapView::attributes)
//   chromaticities       Rec.709 / D65 (the working space)
// Channels R, G, B (float32), plus "confidence" for captured maps and, for captured maps whose
// image had pixels clipped in every bracket, "clipped" (see MapView::clipped). Texel p of view v holds the
// radiance leaving a surface with normal world_from_view * g_normal(p) toward a viewer at infinity
// along v (core/sphere_map.h).
#pragma once

#include "core/central_direction.h"
#include "core/view_set.h"

#include <opencv2/core.hpp>

#include <map>
#include <string>
#include <vector>

namespace rsibr {

// Where a map's radiance came from: a bake (computed) or photographs (captured).
enum class MapSource { Computed, Captured };
const char* to_string(MapSource source);                    // "computed" / "captured"
MapSource map_source_from_string(const std::string& name);  // std::invalid_argument for others

struct MapView {
  Vec3 view = Vec3(0, 0, 1);  // world, unit; stored as float on disk
  Mat3 world_from_view = Mat3::Identity();
  CentralDirection warp = CentralDirection::Mirror;  // which central direction the runtime warps
  MapSource source = MapSource::Computed;
  std::string material;
  // The photo view a captured map was extracted from (its name in the photo set; stored as
  // rsibr.image), which matches a map to its view across balls and steps; "" when none.
  std::string image;
  // Empty, or the albedo table of albedo-normalised maps (core/albedo_normalisation.h): rgb then holds
  // L / A(n.v) and the runtime (runtime/blend_engine.h) multiplies A back at the destination.
  std::vector<float> albedo;
  std::map<std::string, std::string> attributes;  // provenance, written as rsibr.<key>
  cv::Mat rgb;                                    // CV_32FC3, RGB order, sphere-map layout (square or not)
  cv::Mat confidence;                             // empty, or CV_32FC1 of the same size
  // Empty, or CV_32FC1 of the same size: where some of the texel's image samples were clipped in
  // every bracket (their radiance is a lower bound), the confidence the texel would have had without
  // them (its confidence is then 0); 0 elsewhere. "Seen" = confidence > 0 or clipped > 0.
  cv::Mat clipped;
};

struct MapSet {
  std::vector<MapView> views;

  // The triangulated view set of the views' directions (recomputed, never stored).
  ViewSet view_set() const;
  int width() const { return views.empty() ? 0 : views.front().rgb.cols; }
  int height() const { return views.empty() ? 0 : views.front().rgb.rows; }
};

// Checks the invariants (non-empty, equal sizes, unit views, world_from_view a rotation whose
// third column is the view); throws std::invalid_argument naming the
// view and the problem.
void validate(const MapSet& set);

// What a reader does with NaN, Inf and absurd values (core/texel_audit.h) in a file's maps, and
// with confidences that are not finite or outside [0, 1].
enum class BadTexels {
  refuse,  // an error naming the view, the counts and the first texel
  zero,    // colour values zeroed (negative ones too), confidences clamped to [0, 1] (NaN: 0)
};

// Both throw std::runtime_error("<path>: <problem>"). Writing is atomic. `zeroed`, if given,
// receives how many values BadTexels::zero changed.
void write_map_set(const std::string& path, const MapSet& set);
MapSet read_map_set(const std::string& path, BadTexels bad = BadTexels::refuse, long* zeroed = nullptr);

// True when the file is a multi-part EXR whose first part is named "view.000".
bool is_map_set_file(const std::string& path);

}  // namespace rsibr
