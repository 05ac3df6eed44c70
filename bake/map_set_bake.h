// Baking a computed map set: one radiance sphere map per view of a view set, a BRDF integrated
// against an environment by one integrator (bake/integrator.h for what a texel holds), with the
// map-set attributes every computed set carries (formats/map_set.h). Shared by `rsibr bake` and the
// Python module.
#pragma once

#include "bake/brdf.h"
#include "bake/integrator.h"
#include "formats/map_set.h"
#include "core/view_set.h"

#include <functional>
#include <string>
#include <vector>

namespace rsibr {

struct MapSetBakeOptions {
  int res = 128;                 // sphere-map size (square), >= 1
  IntegratorOptions integrator;  // samples, seed, reference width (recorded as attributes)
  // Albedo-normalised maps (core/albedo_normalisation.h): texels hold L / A(n.v), the table is stored.
  bool normalise_albedo = false;
  std::string environment_name;  // provenance: rsibr.environment (the CLI writes the file name)
};

// For every view v of `views`, in order: world_from_view = world_from_view_for(v), warp "normal"
// for Normal-lobe BRDFs and "mirror" otherwise, source "computed", material brdf.spec(), and the
// attributes version, environment, method (integrator.name()), samples and seed ("n/a" for the
// deterministic integrators), referenceWidth (reference only). Same inputs and seed, same maps.
// `progress`, if set, gets the fraction of rows done in [0, 1] (from worker threads).
// Throws std::invalid_argument for a res < 1 and what the integrator throws (e.g. sh with a BRDF
// that is not Lambert).
MapSet bake_map_set(const Brdf& brdf, const Integrator& integrator, const ViewSet& views,
                    const MapSetBakeOptions& options, const std::function<void(double)>& progress = {});

// One map's view and frame: the view v (world, unit, toward the viewer) and world_from_view.
struct BakeFrame {
  Vec3 view;
  Mat3 world_from_view;
};
// The frames bake_map_set(views) uses: world_from_view_for(v) for each view, in order.
std::vector<BakeFrame> frames_of(const ViewSet& views);

// The same bake at given frames (e.g. the captured maps' frames, to compare texel for texel): one
// map per frame, in order, with the same headers. Throws what bake_map_set throws, and
// std::invalid_argument for no frame.
MapSet bake_map_set(const Brdf& brdf, const Integrator& integrator, const std::vector<BakeFrame>& frames,
                    const MapSetBakeOptions& options, const std::function<void(double)>& progress = {});

// The set bake_map_set makes from maps already integrated: radiance[i] is the CV_32FC3 res x res
// map of views.views()[i] that integrator.radiance_map gives (with options.integrator); this adds
// the headers and the albedo normalisation. For bakes split over processes (cluster/), whose
// texels are integrated apart and gathered: the same texels give the same set.
// Throws std::invalid_argument when the counts or sizes do not match.
MapSet computed_map_set(const Brdf& brdf, const Integrator& integrator, const ViewSet& views,
                        const MapSetBakeOptions& options, std::vector<cv::Mat> radiance);
MapSet computed_map_set(const Brdf& brdf, const Integrator& integrator, const std::vector<BakeFrame>& frames,
                        const MapSetBakeOptions& options, std::vector<cv::Mat> radiance);

}  // namespace rsibr
