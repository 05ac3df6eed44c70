#include "runtime/map_shader.h"

namespace rsibr {

const char* const kMeshVertexShader = R"GLSL(#version 330 core
layout(location = 0) in vec3 aPosition;
layout(location = 1) in vec3 aNormal;
uniform mat3 uCamFromWorld;
uniform vec3 uEye;
uniform vec4 uIntrinsics;  // fx, fy, cx, cy (pixels, mrcal convention)
uniform vec2 uSize;        // W, H
uniform vec2 uDepth;       // A, B of clip.z = A q.z + B
out vec3 vNormal;
out vec3 vWorld;
void main() {
  vec3 q = uCamFromWorld * (aPosition - uEye);
  gl_Position = vec4((2.0 * uIntrinsics.x / uSize.x) * q.x + (2.0 * (uIntrinsics.z + 0.5) / uSize.x - 1.0) * q.z,
                     -(2.0 * uIntrinsics.y / uSize.y) * q.y + (1.0 - 2.0 * (uIntrinsics.w + 0.5) / uSize.y) * q.z,
                     uDepth.x * q.z + uDepth.y, q.z);
  vNormal = aNormal;
  vWorld = aPosition;
}
)GLSL";

const char* const kMeshFragmentShader = R"GLSL(
in vec3 vNormal;
in vec3 vWorld;
out vec4 fragColor;

uniform mat3 uWorldFromCam;
uniform vec4 uIntrinsics;   // fx, fy, cx, cy
uniform vec2 uSize;         // W, H of the whole frame
uniform vec2 uOrigin;       // window position of this camera's pixel (0, 0) corner
uniform int uShowWeight;    // 1: output sum_i a_i as grey
uniform float uRimFade;

uniform sampler2DArray uMaps;    // RGBA32F per view: RGB, A = confidence (1 without one)
uniform ivec2 uMapSize;
uniform sampler2D uViewData;     // RGBA32F, width = views; rows 0..2: rows of view_from_world, row 0 .w = kind
uniform isampler2D uTriangles;   // RGBA32I, width = triangles: the three view indices
uniform sampler2D uEdgePlanes;   // RGBA32F, width = triangles, rows 0..2: unit a x b, b x c, c x a
uniform int uTriangleCount;
uniform isampler2D uArcs;        // RGBA32I, width = boundary arcs: views a, b and their triangle
uniform int uArcCount;           // 0 when the set surrounds the sphere
uniform int uHint;               // triangle of the camera's central direction (tried first)

uniform sampler2D uDest;         // paper: RGBA32F destination map, A = weight
uniform ivec2 uDestSize;
uniform mat3 uDestViewFromWorld; // T_d^T

// runtime/disc_sampler.h; returns (rgb, confidence) in .rgb/.a and success in ok. FETCH(c) reads
// texel c of the sampled map (one function per map kind: no per-tap branch).
#define SAMPLE_DISC(NAME, FETCH)                                                                  \
  vec4 NAME(int layer, vec2 xy, ivec2 size, out bool ok) {                                        \
    float W = float(size.x), H = float(size.y);                                                   \
    for (int attempt = 0; attempt < 8; ++attempt) {                                               \
      vec2 p = vec2(0.5 * ((xy.x + 1.0) * W - 1.0), 0.5 * ((1.0 - xy.y) * H - 1.0));              \
      vec2 f0 = floor(p);                                                                         \
      vec2 f = p - f0;                                                                            \
      ivec2 c0 = ivec2(f0);                                                                       \
      ivec2 lo = clamp(c0, ivec2(0), size - 1), hi = clamp(c0 + 1, ivec2(0), size - 1);           \
      vec4 acc = vec4(0.0);                                                                       \
      float total = 0.0;                                                                          \
      for (int j = 0; j < 2; ++j) {                                                               \
        int r = j == 0 ? lo.y : hi.y;                                                             \
        float y = 1.0 - (2.0 * float(r) + 1.0) / H;                                               \
        float wy = j == 0 ? 1.0 - f.y : f.y;                                                      \
        for (int i = 0; i < 2; ++i) {                                                             \
          int c = i == 0 ? lo.x : hi.x;                                                           \
          float w = (i == 0 ? 1.0 - f.x : f.x) * wy;                                              \
          float x = (2.0 * float(c) + 1.0) / W - 1.0;                                             \
          if (!(w > 0.0) || x * x + y * y > 1.0) continue;                                        \
          acc += w * FETCH;                                                                       \
          total += w;                                                                             \
        }                                                                                         \
      }                                                                                           \
      if (total > 0.0) {                                                                          \
        ok = true;                                                                                \
        vec4 s = acc / total;                                                                     \
        s.a = s.a > 0.0 ? s.a : 0.0;                                                              \
        return s;                                                                                 \
      }                                                                                           \
      xy *= 1.0 - 1.0 / float(max(size.x, size.y));                                               \
    }                                                                                             \
    ok = false;                                                                                   \
    return vec4(0.0);                                                                             \
  }
SAMPLE_DISC(sample_disc, texelFetch(uMaps, ivec3(c, r, layer), 0))
SAMPLE_DISC(sample_dest, texelFetch(uDest, ivec2(c, r), 0))

// runtime/warp.cpp warp_direction: (disc.x, disc.y, rim).
vec3 warp_direction(int kind, vec3 d) {
  float len = length(d);
  if (!(len > 0.0)) return vec3(0.0);
  if (kind == 0) {  // mirror: the half vector
    vec3 r = d / len;
    float q = r.x * r.x + r.y * r.y;
    float one_plus_z = r.z >= 0.0 ? 1.0 + r.z : q / (1.0 - r.z);
    float hlen = sqrt(q + one_plus_z * one_plus_z);
    if (!(hlen > 0.0)) return vec3(0.0, -1.0, 0.0);
    return vec3(r.x / hlen, r.y / hlen, one_plus_z / hlen);
  }
  vec2 xy = d.xy / len;
  float rim = d.z / len;
  if (d.z < 0.0) {
    float l2 = dot(xy, xy);
    xy = l2 > 0.0 ? xy / sqrt(l2) : vec2(0.0, -1.0);
  }
  return vec3(xy, rim);
}

// runtime/blend.cpp rim_fade_weight
float rim_fade_weight(float rho) {
  if (!(uRimFade > 0.0)) return 1.0;
  if (!(rho > 0.0)) return 0.0;
  float t = min(rho / uRimFade, 1.0);
  return t * t * (3.0 - 2.0 * t);
}

vec3 view_of(int i) { return texelFetch(uViewData, ivec2(i, 3), 0).xyz; }
// Signed sine of p's angular distance from the triangle's nearest edge circle (positive inside):
// core/view_set.cpp locate's score, min_k det(a_k, a_k+1, p) / |a_k x a_k+1|.
float margin(int t, vec3 p) {
  return min(min(dot(p, texelFetch(uEdgePlanes, ivec2(t, 0), 0).xyz), dot(p, texelFetch(uEdgePlanes, ivec2(t, 1), 0).xyz)),
             dot(p, texelFetch(uEdgePlanes, ivec2(t, 2), 0).xyz));
}
// core/view_set.cpp triangle_weights (gnomonic)
vec3 triangle_weights(vec3 p, vec3 a, vec3 b, vec3 c) {
  vec3 w = max(vec3(dot(p, cross(b - p, c - p)), dot(a, cross(p - a, c - a)), dot(a, cross(b - a, p - a))), 0.0);
  float s = w.x + w.y + w.z;
  if (!(s > 0.0)) {
    float ka = dot(a, p), kb = dot(b, p), kc = dot(c, p);
    if (ka >= kb && ka >= kc) return vec3(1.0, 0.0, 0.0);
    return kb >= kc ? vec3(0.0, 1.0, 0.0) : vec3(0.0, 0.0, 1.0);
  }
  return w / s;
}

// runtime/blend_engine.h, BlendEngine::radiance(v, n); weight in .a
vec4 lookup(vec3 v, vec3 n) {
  float nv = dot(n, v);
  if (nv < 0.0) {
    n -= nv * v;
    float len = length(n);
    vec3 other = abs(v.y) < 0.9 ? vec3(0.0, 1.0, 0.0) : vec3(1.0, 0.0, 0.0);
    n = len > 0.0 ? n / len : normalize(cross(v, cross(other, v)));
    nv = 0.0;
  }
  vec3 r = 2.0 * nv * n - v;
  // Locate (core/view_set.cpp): the hinted triangle when v lies clearly inside it, else the one
  // with the largest margin; outside every triangle of a set that does not surround the sphere, the
  // nearest point q of the nearest boundary arc, with the weights its triangle gives there.
  int best = uHint;
  float best_margin = best >= 0 ? margin(best, v) : -1e30;
  if (!(best_margin > 1e-5)) {
    best_margin = -1e30;
    for (int t = 0; t < uTriangleCount; ++t) {
      float m = margin(t, v);
      if (m > best_margin) { best_margin = m; best = t; }
      if (m > 1e-5) break;  // clearly inside: triangles do not overlap, no other can hold v
    }
  }
  vec3 p = v;
  if (best_margin < -1e-6 && uArcCount > 0) {
    float best_cos = -2.0;
    for (int i = 0; i < uArcCount; ++i) {
      ivec3 arc = texelFetch(uArcs, ivec2(i, 0), 0).xyz;
      vec3 a = view_of(arc.x), b = view_of(arc.y);
      vec3 nab = normalize(cross(a, b));
      vec3 q = v - dot(v, nab) * nab;
      float ql = length(q);
      vec3 qn = ql > 0.0 ? q / ql : a;
      bool on = ql > 1e-7 && dot(a, cross(qn, nab)) >= 0.0 && dot(qn, cross(b, nab)) >= 0.0;
      if (!on) qn = dot(a, v) >= dot(b, v) ? a : b;
      float c = dot(v, qn);
      if (c > best_cos) { best_cos = c; best = arc.z; p = qn; }
    }
  }
  ivec3 T = texelFetch(uTriangles, ivec2(best, 0), 0).xyz;
  vec3 w = triangle_weights(p, view_of(T.x), view_of(T.y), view_of(T.z));
  vec3 acc = vec3(0.0);
  float total = 0.0;
  vec3 s[3];
  for (int k = 0; k < 3; ++k) {
    int id = T[k];
    vec4 row0 = texelFetch(uViewData, ivec2(id, 0), 0);
    mat3 view_from_world = transpose(mat3(row0.xyz, texelFetch(uViewData, ivec2(id, 1), 0).xyz,
                                          texelFetch(uViewData, ivec2(id, 2), 0).xyz));
    int kind = int(row0.w);
    s[k] = warp_direction(kind, view_from_world * (kind == 0 ? r : n));
    if (!(w[k] > 0.0)) continue;
    float a = w[k] * rim_fade_weight(s[k].z);
    if (!(a > 0.0)) continue;
    bool ok;
    vec4 L = sample_disc(id, s[k].xy, uMapSize, ok);
    if (!ok) continue;
    a *= L.a;
    if (!(a > 0.0)) continue;
    acc += a * L.rgb;
    total += a;
  }
  if (total > 0.0) return vec4(acc / total, total);
  int least = 0;
  for (int k = 1; k < 3; ++k)
    if (s[k].z > s[least].z) least = k;
  bool ok;
  vec4 L = sample_disc(T[least], s[least].xy, uMapSize, ok);
  return vec4(ok ? L.rgb : vec3(0.0), 0.0);
}

void main() {
  vec2 px = vec2(gl_FragCoord.x - uOrigin.x - 0.5, uSize.y - (gl_FragCoord.y - uOrigin.y) - 0.5);
  vec3 d = normalize(uWorldFromCam * vec3((px.x - uIntrinsics.z) / uIntrinsics.x,
                                          (px.y - uIntrinsics.w) / uIntrinsics.y, 1.0));
  vec3 v = -d;
  // The interpolated vertex normal, flipped on back faces; where it cancels, the triangle's own
  // normal facing the eye (core/ray_scene.h shading_normal's fallback, then the renderer's flip).
  float nl = length(vNormal);
  vec3 n;
  if (nl > 1e-12) {
    n = vNormal / nl;
    if (!gl_FrontFacing) n = -n;
  } else {
    n = normalize(cross(dFdx(vWorld), dFdy(vWorld)));
    if (!(dot(n, v) >= 0.0)) n = -n;
  }
#if RSIBR_PAPER
  vec3 s = warp_direction(1, uDestViewFromWorld * n);
  bool ok;
  vec4 L = sample_dest(0, s.xy, uDestSize, ok);
  if (!ok) L = vec4(0.0);
#else
  vec4 L = lookup(v, n);
#endif
  fragColor = uShowWeight != 0 ? vec4(vec3(L.a), 1.0) : vec4(L.rgb, 1.0);
}
)GLSL";

std::string webgl2_vertex_shader() {
  const std::string vs = kMeshVertexShader, desktop = "#version 330 core\n";
  return "#version 300 es\nprecision highp float;\n" + vs.substr(vs.rfind(desktop, 0) == 0 ? desktop.size() : 0);
}

std::string webgl2_fragment_shader() {
  return std::string(
             "#version 300 es\nprecision highp float;\nprecision highp int;\nprecision highp sampler2D;\n"
             "precision highp isampler2D;\nprecision highp sampler2DArray;\n#define RSIBR_PAPER 0\n") +
         kMeshFragmentShader;
}

}  // namespace rsibr
