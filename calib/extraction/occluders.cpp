#include "calib/extraction/occluders.h"

#include <algorithm>
#include <cmath>

namespace rsibr {

namespace {

// Squared distance between the ray o + t d (t in [0, T]) and the segment b + s a (s in [0, L]),
// a and d unit: the closest pair of the two lines, each parameter clamped to its range and the
// other re-solved (the standard segment-segment distance).
double ray_segment_dist2(const Vec3& o, const Vec3& d, double T, const Vec3& b, const Vec3& a, double L) {
  const Vec3 w = o - b;
  const double dd = d.dot(a), wd = w.dot(d), wa = w.dot(a);
  const double den = 1 - dd * dd;
  double t = 0, s = 0;
  if (den > 1e-12) {
    t = std::clamp((dd * wa - wd) / den, 0.0, T);
  }
  for (int it = 0; it < 4; ++it) {
    s = std::clamp(wa + t * dd, 0.0, L);
    t = std::clamp(s * dd - wd, 0.0, T);
  }
  s = std::clamp(wa + t * dd, 0.0, L);
  return (w + t * d - s * a).squaredNorm();
}

}  // namespace

bool ray_hits(const Occluder& occ, const Vec3& o, const Vec3& d, double t_max) {
  if (occ.kind == Occluder::sphere) {
    const Vec3 oc = occ.centre - o;
    const double t = std::clamp(oc.dot(d), 0.0, t_max);
    return (oc - t * d).squaredNorm() < occ.radius * occ.radius;
  }
  return ray_segment_dist2(o, d, t_max, occ.centre, occ.axis, occ.length) < occ.radius * occ.radius;
}

std::vector<Occluder> chrome_occluders(const BallCone& chrome, const std::vector<OtherBall>& others,
                                       const std::optional<Vec3>& down_cam, double chrome_radius_m,
                                       const OccluderOptions& o) {
  std::vector<Occluder> out;
  const Vec3 c = chrome.axis.normalized() / std::sin(chrome.half_angle);
  const double per_m = 1.0 / chrome_radius_m;  // chrome radii per metre
  for (const OtherBall& b : others) {
    Occluder s;
    s.kind = Occluder::sphere;
    s.centre = b.scale * b.cone.axis.normalized() / std::sin(b.cone.half_angle);
    s.radius = o.ball_margin * b.scale;
    s.what = "ball " + b.name;
    out.push_back(s);
  }
  if (!down_cam) return out;
  const Vec3 down = down_cam->normalized();
  auto stand = [&](const Vec3& centre, double radius, const std::string& name) {
    Occluder p;
    p.kind = Occluder::capsule;
    p.centre = centre + 0.9 * radius * down;
    p.axis = down;
    p.length = o.stand_length_m * per_m;
    p.radius = o.stand_radius * radius;
    p.what = "stand under " + name;
    out.push_back(p);
  };
  stand(c, 1.0, "the chrome ball");
  for (const OtherBall& b : others)
    stand(b.scale * b.cone.axis.normalized() / std::sin(b.cone.half_angle), b.scale, b.name);
  if (o.photographer) {
    // Behind the camera: its forward axis made horizontal, reversed.
    Vec3 back = -(Vec3(0, 0, 1) - down.z() * down);
    if (back.norm() < 1e-6) back = Vec3(0, 1, 0) - down.y() * down;
    back.normalize();
    Occluder p;
    p.kind = Occluder::capsule;
    p.centre = (o.photographer_behind_m * back - o.photographer_above_m * down) * per_m;
    p.axis = down;
    p.length = (o.photographer_above_m + o.photographer_below_m) * per_m;
    p.radius = o.photographer_radius_m * per_m;
    p.what = "photographer";
    out.push_back(p);
  }
  return out;
}

}  // namespace rsibr
