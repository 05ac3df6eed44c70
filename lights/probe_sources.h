// Writing recovered light sources (lights/light_source.h) into a lat-long probe, energy-preserving
// at the probe's resolution, and their provenance (the probe's header and JSON summaries).
//
// For each source of power P (RGB), texel weights w_t >= 0 with sum_t w_t = 1 are chosen and
// texel t gets P w_t / Omega_t added, so sum_t Omega_t * (added L_t) = P exactly:
//   a disc wider than its texels (solid angle above twice the texel's at its direction):
//     w_t = cov_t Omega_t / sum(cov Omega), cov_t the fraction of an 8 x 8 grid of points of
//     texel t inside the disc (the disc's uniform radiance, its shape at the probe's resolution);
//   a smaller one (a sun at 256 texels wide): its power bilinearly splatted to the 4 texels around
//     its direction (w_t the bilinear weights), which keeps its centroid to first order.
#pragma once

#include "core/env_map.h"
#include "lights/light_source.h"

#include <nlohmann/json.hpp>

#include <vector>

namespace rsibr {

// probe: lat-long, >= 3 channels (RGB used). Returns each source's footprint: the solid angle of
// the texels it went into, weighted (sum_t w_t Omega_t ... as the effective Omega of its radiance).
std::vector<double> add_sources_to_probe(EnvMap& probe, const std::vector<LightSource>& sources);

// One JSON object per source: direction (and azimuth / elevation in degrees), radius (degrees,
// whether fitted), solid angle in the probe (sr), radiance there (power / solid angle), power,
// its sigma, the direction's sigma (degrees), the balls and views that constrained it, and its
// clipped region (solid angle, radius, lower bound of its power).
nlohmann::json light_sources_json(const std::vector<LightSource>& sources, const std::vector<double>& footprints);

// The probe header's attributes: rsibr.lightSources (the JSON above, compact) and
// rsibr.lightSourceCount.
void set_light_source_attributes(EnvMap& probe, const nlohmann::json& sources);

}  // namespace rsibr
