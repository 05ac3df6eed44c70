// The light probe: chrome-ball sphere maps of several views (captured map sets from extraction, in
// one world frame) blended into one lat-long environment, each view weighted by its confidence
// channel (0 at the camera's reflection, the stand, clipped pixels; fading at the stretched rim), so
// every view's camera and rim are filled by the others.
//
// For a world direction w and a view with frame T (world_from_view): r = T^T w, texel at
// g_mirror_inv(r) (core/sphere_map.h), RGB and confidence bilinear. A chrome map holds F(cos) L(w)
// with cos = n.v = sqrt((1 + r.z) / 2) (the half angle); `fresnel`, when given, is divided out so the
// probe holds L. Texels whose summed confidence is below min_weight are 0 (no view saw them).
//
// Energy: a probe texel is the mean of k x k lookups over its cell, k = clamp(ceil(texel angle /
// map texel angle), 1, 4) (a map texel spans 4 / size radians: the sphere map is equal-area, 4 sr
// per unit of disc area), so a probe coarser than the maps still sums their energy; a finer one
// reads the maps' bilinear reconstruction, which keeps it.
//
// Clipped light: a view's lookup with a clipped tap (the map's `clipped` channel, formats/map_set.h)
// counts as clipped as a whole (the tap's value is a lower bound; renormalising over its trusted
// neighbours would fill a sun with sky). Where no view has an unclipped lookup but some view a
// clipped one, or the clipped lookups outweigh the unclipped ones (those within registration_deg
// of their own view's clipped texels abstain: they saw the light clipped nearby) and the unclipped blend is darker
// than the largest lower bound (it contradicts them: a sun smeared over the stretched rim of a view
// that saw it unclipped), the probe
// texel is 0, `clipped` holds the summed weight of the clipped lookups (the direction counts as
// clipped in every bracket of every chrome view that saw it) and `lower_bound` the largest of
// their values (each a lower bound of F L, F divided out).
#pragma once

#include "bake/fresnel.h"
#include "core/env_map.h"
#include "formats/map_set.h"

namespace rsibr {

// The chrome ball's reflectance when the user states none (rsibr probe --fresnel, rsibr process
// --chrome-fresnel): a conductor with chromium-like optical constants, n = 2.9 / 2.9 / 2.6 and
// k = 3.4 / 3.4 / 3.2 (R / G / B), about 57% at normal incidence and rising to 1 at grazing, as
// chrome-plated steel balls measure (55-65% across the visible). "none" keeps F L in the probe.
// What a texel of a finished probe (DIR/probe.exr) is, in its `flags` channel; its `confidence`
// channel is the summed confidence of the views' trusted lookups (Probe::weight), 0 unless measured.
//   kProbeLowerBound  clipped in every view that saw it and not recovered: the largest clipped
//                     value (Probe::lower_bound); the light there is at least this
//   kProbeSource      clipped, and a light source recovered from the grey balls lies there
//   kProbeFilled      no view saw it (behind the ball, the stand, the masked camera): filled from
//                     the seen surroundings (calib/probe/probe_fill.h), no measurement
enum ProbeFlag : unsigned char { kProbeLowerBound = 1, kProbeSource = 2, kProbeFilled = 4 };

inline constexpr const char* kDefaultChromeFresnel = "{type: conductor, eta: [2.9, 2.9, 2.6], k: [3.4, 3.4, 3.2]}";

struct ProbeOptions {
  int width = 256;                   // lat-long width (height = width / 2)
  const Fresnel* fresnel = nullptr;  // the ball's Fresnel, divided out; none: the probe is F L
  double min_weight = 1e-3;
  // How far the views' frames may disagree (degrees): a trusted lookup this close to its own view's
  // clipped texels abstains from the vote against the other views' lower bounds (probe.cpp; why 2:
  // docs/tradeoffs.md, "Measured choices in the code").
  double registration_deg = 2.0;
};

struct Probe {
  EnvMap env;                   // lat-long, RGB
  cv::Mat weight;               // CV_32FC1, summed confidence per texel
  cv::Mat clipped;              // CV_32FC1, summed weight of the clipped lookups at clipped texels (0 elsewhere)
  cv::Mat lower_bound;          // CV_32FC3, the largest lower bound of L seen there (0 elsewhere)
  double covered_fraction = 0;  // solid-angle fraction with weight >= min_weight
  double clipped_fraction = 0;  // solid-angle fraction of texels clipped in every view that saw them
};

// Throws std::invalid_argument when the set is empty or has no confidence channel (not captured).
Probe assemble_probe(const MapSet& chrome, const ProbeOptions& options = {});

// The jackknife's probes: per view v, the env of assemble_probe(the set without view v), bit for bit,
// made in one pass over the texels (each view's lookups made once; the views' folds reuse them).
// With one view, its fold is an empty EnvMap. Throws as assemble_probe.
std::vector<EnvMap> assemble_probe_folds(const MapSet& chrome, const ProbeOptions& options = {});

// Writes a finished probe atomically: R, G, B and the `confidence` and `flags` channels (CV_32FC1
// and CV_8UC1 of the map's size; ProbeFlag bits). Throws FileError(path, problem).
void write_probe(const std::string& path, const EnvMap& env, const cv::Mat& confidence, const cv::Mat& flags);

}  // namespace rsibr
