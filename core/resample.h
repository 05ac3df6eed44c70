// Resampling an environment map from any layout to any other.
//
// Each destination texel is the solid-angle-weighted mean of the source over the texel's cell:
//   L_dst(p) = int_cell L_src(w(q)) dOmega(q) / int_cell dOmega(q),
// estimated with an n x n grid of bilinear source taps inside the cell, weighted by the
// destination's solid-angle density. n grows with the footprint k: the cell's largest angular
// extent divided by the source texel's smallest angular size there (the singular values of each
// layout's pixel -> direction Jacobian), so shrinking never aliases, a compact bright source (a sun
// of one texel) keeps its energy, and enlarging several-fold is plain bilinear (n = 1).
#pragma once

#include "core/env_map.h"

#include <functional>

namespace rsibr {

enum class Reconstruction {
  Bilinear,  // smooth; what views and renders want
  Nearest,   // piecewise constant: integrates exactly to sum L*Omega (MIP levels, energy budgets)
};

struct ResampleOptions {
  Reconstruction reconstruction = Reconstruction::Bilinear;
  // Taps per source texel along the footprint's longest side: n = ceil(supersampling * k) where k
  // is the footprint in source texels. 1 is plain area sampling; 4 integrates a one-texel sun to
  // ~1e-3 of its energy. Enlarging by more than this factor is plain bilinear (n = 1).
  double supersampling = 4.0;
  int max_subsamples = 32;  // cap on n (n x n taps per destination texel)
  // Energy budget per texel, relative to the whole map's energy: where the source is much brighter
  // than its mean (a sun, or ringing around one), n also grows until
  //   peak * Omega_texel / n^2 <= energy_tolerance * integral(|L|),
  // so a compact source keeps its energy. Costs taps only at those few texels; 0 disables.
  double energy_tolerance = 1e-4;
  // From a lat-long source (bilinear): a texel's taps are placed by interpolating the exact source
  // positions at its corners (checked at its centre) and read from the level of a longitude ripmap
  // whose texels are square at that latitude (core/latlong_ripmap.h); texels the check refuses, or
  // that may hold more than a tenth of energy_tolerance of the map, take the exact path. false:
  // every tap's direction is computed (the reference the interpolated taps are tested against).
  bool interpolate_taps = true;
  // Called with the fraction done (0..1), from worker threads (must be thread-safe); may be empty.
  std::function<void(double)> progress;
};

EnvMap resample(const EnvMap& src, const Layout& dst, const ResampleOptions& options = {});

// Angular size of a pixel step at a position: the smallest and largest singular values (radians
// per pixel) of the layout's pixel -> direction Jacobian, by central differences (one-sided at the
// sphere layout's rim).
struct PixelFootprint {
  double min_radians = 0;
  double max_radians = 0;
};
PixelFootprint pixel_footprint(const Layout& layout, const Vec2& pixel);

}  // namespace rsibr
