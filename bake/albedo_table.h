// A BRDF's directional albedo as a function of cos(theta_o) alone, tabulated for albedo-normalised
// maps (the map-set attribute rsibr.albedo; formats/map_set.h, runtime/blend.h).
//
// Why: a radiance map is view dependent mostly through a factor that depends on the outgoing angle
// only (Fresnel: the coat's reflectance rises toward 1 at grazing; the coat transmittance T(wo) of
// a clear coat's binder). Storing L(n, v) / A(n.v) and multiplying the blend by A(n.d) at the
// destination moves that factor out of what the warp has to carry:
//
//   L(n, v) = A(n.v) * P(n, v),    P = L / A  (the "normalised" map; for the clear coat's normal
//                                              part exactly view independent: L = T(n.v) <T-weighted
//                                              irradiance of n>, and A = T(n.v) <T>(1-c) rho)
//
// Table: A at cos_k = (k + 0.5) / N, k = 0..N-1, RGB; between samples linear, outside clamped to the
// end samples. An isotropic BRDF's albedo depends on theta_o only (wo = (sin, 0, cos) locally).
#pragma once

#include "bake/brdf.h"

#include <vector>

namespace rsibr {

// Rows of (r, g, b), N >= 2; every value finite and >= 0. Throws std::invalid_argument otherwise.
std::vector<float> albedo_table(const Brdf& brdf, int samples = 128);

}  // namespace rsibr
