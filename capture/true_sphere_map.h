// The true sphere map of one ball seen from one camera (the truth that extraction is tested
// against), in the view frame of docs/conventions.md: v = unit vector from the ball centre toward the camera
// centre, world_from_view = world_from_view_for(v) (core/vec.h). Texel p (centre inside the disc):
//   chrome   F(n.v) * L_env(2 (n.v) n - v),  n = world_from_view * g_normal(p)   (a perfect mirror
//            with the ball's Fresnel; the environment sampled bilinearly as the renderer does)
//   grey     Lambert: albedo * E(n) / pi, E by capture/irradiance.h's quadrature at the texel's
//            normal (bright texels at full resolution, the rest on a 128-wide MIP level)
//   glossy   the ball's BRDF baked by bake/'s filtered importance sampling integrator (64 samples,
//            seed 0): the integral of L_env against the BRDF for viewer v
// Texels outside the disc are 0. The camera body, photographer and stand are NOT in these maps
// (the photos show them; extraction must remove them).
#pragma once

#include "bake/integrator.h"
#include "capture/irradiance.h"
#include "capture/synth_scene.h"
#include "core/env_map.h"
#include "formats/map_set.h"

namespace rsibr {

// `irradiance`, when given, must be IrradianceQuadrature(env), and `fis` make_integrator("fis", env)
// (both reused across views and balls).
MapView true_sphere_map(const SynthBall& ball, const Vec3& camera_centre, const EnvMap& env, int size,
                        const IrradianceQuadrature* irradiance = nullptr, const Integrator* fis = nullptr);

}  // namespace rsibr
