// Albedo-normalised radiance maps (bake/albedo_table.h says why). A map view may carry a table A of
// its BRDF's directional albedo against cos(theta_o) (MapView::albedo, attribute rsibr.albedo); its
// texels then hold L(n, v) / A(n.v), and the runtime multiplies what it blends by A(n.d) for the
// destination direction d. In a sphere map's own frame n.v is the texel's g_normal z.
//
// Table layout: N >= 2 rows of (r, g, b) at cos_k = (k + 0.5) / N; linear between rows, clamped to
// the end rows outside [0.5/N, 1 - 0.5/N]. Division guards: where A <= kAlbedoFloor the stored value
// is 0 (the radiance is then 0 to within the same bound, since L <= A * max radiance); results are
// clamped to the float range, so no Inf comes out of a finite map.
#pragma once

#include "core/vec.h"

#include <opencv2/core.hpp>

#include <vector>

namespace rsibr {

inline constexpr float kAlbedoFloor = 1e-12f;

// Throws std::invalid_argument unless the table has >= 2 rows of 3 finite values >= 0.
void check_albedo_table(const std::vector<float>& table);

// A(cos) for cos in [0, 1] (values outside are clamped), RGB. The table must be valid.
Vec3 albedo_at(const std::vector<float>& table, float cos_theta);

// In place, for a CV_32FC3 sphere map in its own view frame (texels outside the disc untouched):
// normalise divides each texel inside the disc by A(z), denormalise multiplies by A(z).
void normalise_by_albedo(cv::Mat& rgb, const std::vector<float>& table);
void denormalise_by_albedo(cv::Mat& rgb, const std::vector<float>& table);

}  // namespace rsibr
