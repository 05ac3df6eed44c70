#include "capture/ball_rig.h"

#include <cmath>

namespace rsibr {
namespace {

void add_quad(RigMesh& out, const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d, const Vec3& albedo) {
  const auto base = std::uint32_t(out.mesh.positions.size());
  const Vec3 n = (b - a).cross(c - a).normalized();
  for (const Vec3* p : {&a, &b, &c, &d}) {
    out.mesh.positions.push_back(p->cast<float>());
    out.mesh.normals.push_back(n.cast<float>());
  }
  out.mesh.triangles.push_back({base, base + 1, base + 2});
  out.mesh.triangles.push_back({base, base + 2, base + 3});
  out.albedo.push_back(albedo);
  out.albedo.push_back(albedo);
}

// An oriented box: corners world_from_local * (lo..hi) + origin.
void add_box(RigMesh& out, const Mat3& world_from_local, const Vec3& origin, const Vec3& lo, const Vec3& hi,
             const Vec3& albedo) {
  auto P = [&](int i) {
    const Vec3 l((i & 1) ? hi.x() : lo.x(), (i & 2) ? hi.y() : lo.y(), (i & 4) ? hi.z() : lo.z());
    return Vec3(world_from_local * l + origin);
  };
  // Faces wound counter-clockwise seen from outside (in a right-handed local frame).
  const int faces[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  const bool flip = world_from_local.determinant() < 0;
  for (const auto& f : faces) {
    if (flip)
      add_quad(out, P(f[0]), P(f[3]), P(f[2]), P(f[1]), albedo);
    else
      add_quad(out, P(f[0]), P(f[1]), P(f[2]), P(f[3]), albedo);
  }
}

// A vertical cylinder (no caps) from y0 to y1 about (x, z), smooth vertex normals.
void add_pole(RigMesh& out, double x, double z, double y0, double y1, double radius, const Vec3& albedo) {
  const int segments = 16;
  const auto base = std::uint32_t(out.mesh.positions.size());
  for (int i = 0; i < segments; ++i) {
    const double a = 2 * kPi * i / segments;
    const Vec3 n(std::sin(a), 0, std::cos(a));
    for (double y : {y0, y1}) {
      out.mesh.positions.push_back(Vec3(x + radius * n.x(), y, z + radius * n.z()).cast<float>());
      out.mesh.normals.push_back(n.cast<float>());
    }
  }
  for (int i = 0; i < segments; ++i) {
    const std::uint32_t a = base + 2 * std::uint32_t(i), b = base + 2 * std::uint32_t((i + 1) % segments);
    out.mesh.triangles.push_back({a, b, b + 1});
    out.mesh.triangles.push_back({a, b + 1, a + 1});
    out.albedo.push_back(albedo);
    out.albedo.push_back(albedo);
  }
}

// A flat disc (centre c, normal n) as `rings` concentric annuli of alternating albedo, 96 segments.
void add_disc(RigMesh& out, const SynthClutter& d, const Vec3& normal) {
  const int segments = 96;
  const Vec3 u = normal.unitOrthogonal(), v = normal.cross(u);
  for (int k = 0; k < d.rings; ++k) {
    const double r0 = d.radius_m * k / d.rings, r1 = d.radius_m * (k + 1) / d.rings;
    const Vec3& albedo = k % 2 == 0 ? d.albedo : d.ring_albedo;
    for (int i = 0; i < segments; ++i) {
      const double a0 = 2 * kPi * i / segments, a1 = 2 * kPi * (i + 1) / segments;
      const Vec3 e0 = std::cos(a0) * u + std::sin(a0) * v, e1 = std::cos(a1) * u + std::sin(a1) * v;
      // Counter-clockwise about the normal.
      add_quad(out, d.centre + r0 * e0, d.centre + r1 * e0, d.centre + r1 * e1, d.centre + r0 * e1, albedo);
    }
  }
}

// A UV sphere, 64 x 128 segments, smooth (exact) vertex normals.
void add_sphere(RigMesh& out, const SynthClutter& s) {
  const int rows = 64, cols = 128;
  const auto base = std::uint32_t(out.mesh.positions.size());
  for (int i = 0; i <= rows; ++i)
    for (int j = 0; j <= cols; ++j) {
      const double th = kPi * i / rows, ph = 2 * kPi * j / cols;
      const Vec3 n(std::sin(th) * std::cos(ph), std::cos(th), std::sin(th) * std::sin(ph));
      out.mesh.positions.push_back(Vec3(s.centre + s.radius_m * n).cast<float>());
      out.mesh.normals.push_back(n.cast<float>());
    }
  auto at = [&](int i, int j) { return base + std::uint32_t(i * (cols + 1) + j); };
  for (int i = 0; i < rows; ++i)
    for (int j = 0; j < cols; ++j) {
      if (i > 0) out.mesh.triangles.push_back({at(i, j), at(i, j + 1), at(i + 1, j)}), out.albedo.push_back(s.albedo);
      if (i + 1 < rows)
        out.mesh.triangles.push_back({at(i, j + 1), at(i + 1, j + 1), at(i + 1, j)}), out.albedo.push_back(s.albedo);
    }
}

}  // namespace

RigMesh build_rig_mesh(const SynthScene& scene, const CameraPose* pose) {
  RigMesh out;
  if (scene.stand)
    for (const SynthBall& b : scene.balls) {
      const double bottom = b.centre.y() - 0.5 * b.diameter_m;
      // The pole ends a little inside the ball so no gap shows where it holds it.
      if (bottom > 0)
        add_pole(out, b.centre.x(), b.centre.z(), 0.0, bottom + 0.2 * b.diameter_m, kStandRadius,
                 Vec3::Constant(kStandAlbedo));
    }
  for (const SynthClutter& c : scene.clutter) {
    if (c.shape == "sphere") {
      add_sphere(out, c);
    } else {
      Vec3 n = c.normal.value_or(scene.rig_centre() - c.centre);
      if (!(n.norm() > 0)) n = Vec3::UnitZ();
      add_disc(out, c, n.normalized());
    }
  }
  if (pose && scene.photographer) {
    const Mat3& R = pose->world_from_cam;
    add_box(out, R, pose->eye, Vec3(-0.07, -0.05, -0.09), Vec3(0.07, 0.05, -0.01), Vec3::Constant(kCameraBodyAlbedo));
    add_box(out, R, pose->eye, Vec3(-0.09, -0.12, -0.32), Vec3(0.09, 0.1, -0.12), Vec3::Constant(kPhotographerAlbedo));
    add_box(out, R, pose->eye, Vec3(-0.22, 0.12, -0.42), Vec3(0.22, 0.8, -0.16), Vec3::Constant(kPhotographerAlbedo));
  }
  return out;
}

std::optional<double> intersect_sphere(const Vec3& o, const Vec3& d, const Vec3& c, double r, double t_min) {
  const Vec3 oc = o - c;
  const double b = oc.dot(d);
  const Vec3 h = oc - b * d;  // closest approach of the line to the centre
  const double disc = r * r - h.squaredNorm();
  if (disc < 0) return std::nullopt;
  const double s = std::sqrt(disc);
  // Roots -b -+ s; the near one from the stable product form when b > 0 would cancel.
  const double q = b > 0 ? -b - s : -b + s;
  double t0 = -b - s, t1 = -b + s;
  if (b > 0 && q != 0) t0 = (oc.squaredNorm() - r * r) / q, t1 = q;
  if (t0 > t1) std::swap(t0, t1);
  if (t0 > t_min) return t0;
  if (t1 > t_min) return t1;
  return std::nullopt;
}

}  // namespace rsibr
