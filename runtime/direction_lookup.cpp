#include "runtime/direction_lookup.h"

#include "core/albedo_normalisation.h"

#include <algorithm>
#include <stdexcept>

namespace rsibr {

namespace {
// v / |v|, as core/view_set.cpp's locate normalises (so the hinted weights are bitwise its weights).
Vec3 unit(const Vec3& v) {
  const double sq = v.squaredNorm();
  if (sq > 1e-290 && sq < 1e290) return v.normalized();
  return (v / v.cwiseAbs().maxCoeff()).normalized();
}
double det3(const Vec3& a, const Vec3& b, const Vec3& c) { return a.dot(b.cross(c)); }
}  // namespace

DirectionLookup::DirectionLookup(const MapSet& maps, const ViewSet& view_set, const BlendOptions& options)
    : maps_(maps), view_set_(view_set), options_(options) {
  check_blend_inputs(maps, view_set);
  sources_.resize(maps.views.size());
  for (std::size_t i = 0; i < maps.views.size(); ++i) {
    check_blend_source(maps, int(i));
    const MapView& v = maps.views[i];
    Source& s = sources_[i];
    s.rgb = &v.rgb;
    s.confidence = options.use_confidence && !v.confidence.empty() ? &v.confidence : nullptr;
    s.width = v.rgb.cols;
    s.height = v.rgb.rows;
    s.kind = warp_kind_from_string(v.warp);
    s.view_from_world = v.world_from_view.transpose();
  }
  const auto& views = view_set.views();
  for (const auto& T : view_set.triangles()) {
    const Vec3 &a = views[std::size_t(T[0])], &b = views[std::size_t(T[1])], &c = views[std::size_t(T[2])];
    edge_norms_.push_back({a.cross(b).norm(), b.cross(c).norm(), c.cross(a).norm()});
  }
}

ViewWeights DirectionLookup::locate(const Vec3& v, int* hint) const {
  if (hint && *hint >= 0 && std::size_t(*hint) < view_set_.triangles().size() && v.allFinite() &&
      v.cwiseAbs().maxCoeff() > 0) {
    const auto& T = view_set_.triangles()[std::size_t(*hint)];
    const auto& views = view_set_.views();
    const Vec3 &a = views[std::size_t(T[0])], &b = views[std::size_t(T[1])], &c = views[std::size_t(T[2])];
    const Vec3 p = unit(v);
    // The triangles of a view set do not overlap, so a point this far inside one is in no other.
    constexpr double kInside = 1e-9;
    const auto& e = edge_norms_[std::size_t(*hint)];
    if (det3(a, b, p) > kInside * e[0] && det3(b, c, p) > kInside * e[1] && det3(c, a, p) > kInside * e[2]) {
      ViewWeights out;
      out.count = 3;
      out.views = T;
      out.weights = triangle_weights(p, a, b, c, options_.barycentric);
      out.triangle = *hint;
      out.inside = true;
      out.distance = 0;
      return out;
    }
  }
  ViewWeights out = view_set_.locate(v, options_.barycentric);
  if (hint) *hint = out.triangle;
  return out;
}

Vec3 DirectionLookup::radiance(const ViewWeights& located, const Vec3& v, const Vec3& n_in, double* weight) const {
  // 0. Clamp n to v's hemisphere (the nearest rim normal).
  Vec3 n = n_in;
  double nv = n.dot(v);
  if (nv < 0) {
    n -= nv * v;
    const double len = n.norm();
    n = len > 0 ? Vec3(n / len) : Vec3(-world_from_view_for(v).col(1));
    nv = 0;
  }
  const Vec3 r = 2.0 * nv * n - v;
  // Albedo-normalised sets: the blend of stored texels times A(n.v) (core/albedo_normalisation.h).
  const std::vector<float>& albedo = maps_.views.front().albedo;
  const Vec3 A = albedo.empty() ? Vec3(1, 1, 1) : albedo_at(albedo, float(nv));

  // 2-4.
  double acc[3] = {0, 0, 0}, total = 0;
  WarpSample samples[3];
  for (int k = 0; k < located.count; ++k) {
    const Source& s = sources_[std::size_t(located.views[std::size_t(k)])];
    samples[k] = warp_direction(s.kind, s.view_from_world * (s.kind == WarpKind::Mirror ? r : n));
    const double w = located.weights[std::size_t(k)];
    if (!(w > 0)) continue;
    double a = w * rim_fade_weight(samples[k].rim, options_.rim_fade);
    if (!(a > 0)) continue;
    double L[3], conf;
    if (!sample_disc(s, samples[k].disc, L, &conf)) continue;
    a *= conf;
    if (!(a > 0)) continue;
    acc[0] += a * L[0];
    acc[1] += a * L[1];
    acc[2] += a * L[2];
    total += a;
  }
  if (total > 0) {
    if (weight) *weight = total;
    const double inv = 1.0 / total;
    return Vec3(acc[0] * inv, acc[1] * inv, acc[2] * inv).cwiseProduct(A);
  }
  // 5. Fallback: the least-faded located source, weight 0.
  if (weight) *weight = 0;
  int best = -1;
  for (int k = 0; k < located.count; ++k)
    if (best < 0 || samples[k].rim > samples[best].rim) best = k;
  double L[3], conf;
  if (best >= 0 && sample_disc(sources_[std::size_t(located.views[std::size_t(best)])], samples[best].disc, L, &conf))
    return Vec3(L[0], L[1], L[2]).cwiseProduct(A);
  return Vec3::Zero();
}

}  // namespace rsibr
