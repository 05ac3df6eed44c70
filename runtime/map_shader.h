// The GLSL of the viewer's mesh pass: the runtime's formulas per fragment (OpenGL 3.3 core), and the
// same source for WebGL2 (GLSL ES 3.00: only the version line and default precisions differ), which
// the report's page viewer runs (runtime/web_viewer_page.h): one rule, not a second copy.
//
// Vertex stage: world positions through the mrcal pinhole (core/camera.h) into clip space, so that
// the fragment at window position (x, y) of a W x H frame is image pixel (x - 1/2, H - y - 1/2):
//   q = cam_from_world (p - eye),  u = fx q.x/q.z + cx,  v = fy q.y/q.z + cy,
//   clip = ( (2 fx/W) q.x + (2 (cx + 1/2)/W - 1) q.z,  -(2 fy/H) q.y + (1 - 2 (cy + 1/2)/H) q.z,
//            A q.z + B,  q.z ),   so  clip.x/clip.w = 2 (u + 1/2)/W - 1,  clip.y/clip.w = 1 - 2 (v + 1/2)/H.
// The frame is read back bottom row first and flipped, so on-screen winding is the image's and
// gl_FrontFacing (counter-clockwise front, core/mesh.h) is the renderer's back-face test
// (runtime/renderer.h: the shading normal is flipped where the geometric normal faces away).
//
// Fragment stage, the same definitions as the CPU engine (runtime/blend_engine.h; float32 there too,
// but its warp into a source is double in radiance()):
//   v = -(ray direction through the pixel centre)         (Camera::ray_direction, not the
//                                                          interpolated position: the same ray)
//   n = normalise(interpolated vertex normal), flipped on back faces
//   per-pixel mode: runtime/blend_engine.h, radiance(v, n): n clamped to v's hemisphere,
//     r = 2 (n.v) n - v; v located in the view set (core/view_set.cpp: the spherical triangle with
//     the largest margin; outside a non-surrounding set, the nearest point of the nearest boundary
//     arc with its triangle's weights there,
//     gnomonic weights det(p,b-p,c-p) : det(a,p-a,c-a) : det(a,b-a,p-a) clamped at 0 and normalised,
//     core/view_set.cpp triangle_weights); per source warp_direction (runtime/warp.cpp: half vector
//     with the 1 + r_z cancellation avoided, or the normal with its rim clamp), rim_fade_weight
//     (smoothstep of rho / rim_fade), confidence, sample_disc (runtime/disc_sampler.h: four bilinear
//     taps, taps outside the disc dropped and renormalised, up to 8 inward steps), per-pixel
//     normalisation, and the least-faded-source fallback with weight 0.
//   paper mode: the CPU engine's destination map (runtime/blend.h), read at warp_direction(normal,
//     T_d^T n) with sample_disc (runtime/renderer.h, paper mode).
// Output: RGB radiance, alpha 1 (the renderer's alpha for a covered pixel at 1 sample per pixel); or,
// with uShowWeight, the total weight sum_i a_i as grey (the singularity fades made visible).
// Differences from the CPU path (stated in tests/viewer/gl_renderer_test.cpp with the tolerance):
// float32 arithmetic; ties exactly on a triangle edge or equidistant boundary arcs (both sides give
// the same weights there); the measure-zero n = -v case takes another rim normal.
#pragma once

#include <string>

namespace rsibr {

extern const char* const kMeshVertexShader;
// Without its "#version" line: compiled twice, after "#version 330 core\n#define RSIBR_PAPER 0" (per
// pixel) and "... 1" (paper), so that each program holds one path only.
extern const char* const kMeshFragmentShader;

// The per-pixel program for WebGL2: the shaders above after "#version 300 es" and high precision
// for floats, integers and every sampler type they use.
std::string webgl2_vertex_shader();
std::string webgl2_fragment_shader();

}  // namespace rsibr
