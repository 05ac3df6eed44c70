// Ray queries against a triangle mesh through Embree 3: the visibility engine shared by the
// reference path tracer (bake/), the runtime renderer and the synthetic capture renderer.
//
// Contract: rays are (origin, unit direction) in the mesh's frame (world); hits are reported for
// t in [t_near, t_far]. Both faces of every triangle are hit (no culling). The scene is immutable
// after construction and every query is safe to call from many threads at once.
#pragma once

#include "core/mesh.h"
#include "core/vec.h"

#include <cstdint>
#include <limits>
#include <memory>

namespace rsibr {

struct RayHit {
  bool hit = false;
  double t = 0;                // distance along the (unit) direction
  std::uint32_t triangle = 0;  // index into Mesh::triangles
  double u = 0, v = 0;         // barycentrics of vertices 1 and 2 (vertex 0 has 1 - u - v)
};

class RayScene {
 public:
  // Keeps a reference to `mesh` (which must outlive the scene) for the shading queries. Throws
  // std::runtime_error when Embree cannot build the scene.
  explicit RayScene(const Mesh& mesh);
  ~RayScene();
  RayScene(const RayScene&) = delete;
  RayScene& operator=(const RayScene&) = delete;

  RayHit intersect(const Vec3& origin, const Vec3& direction, double t_near = 0,
                   double t_far = std::numeric_limits<double>::infinity()) const;
  // Many rays from one origin at once (e.g. a camera's primary rays), traced as Embree packets of 16:
  // hits[i] for directions[i] (unit), i < count, with intersect()'s contract. Order the directions so
  // that each run of 16 is coherent (a 4 x 4 pixel block) for speed. Hits agree with intersect() up to
  // Embree's packet arithmetic (same triangle except on shared edges, t to float precision).
  void intersect_coherent(const Vec3& origin, const Vec3* directions, int count, RayHit* hits, double t_near = 0,
                          double t_far = std::numeric_limits<double>::infinity()) const;
  // Whether anything is hit in [t_near, t_far] (cheaper than intersect: any hit ends the query).
  bool occluded(const Vec3& origin, const Vec3& direction, double t_near = 0,
                double t_far = std::numeric_limits<double>::infinity()) const;

  const Mesh& mesh() const { return mesh_; }
  // The hit point interpolated from the triangle's vertices (more accurate than origin + t dir).
  Vec3 position(const RayHit& hit) const;
  // Unit geometric normal of the hit triangle, on the side its vertices wind counter-clockwise.
  Vec3 geometric_normal(const RayHit& hit) const;
  // Unit shading normal: the vertex normals interpolated with the hit's barycentrics (falls back
  // to the geometric normal where they cancel).
  Vec3 shading_normal(const RayHit& hit) const;

 private:
  struct Impl;
  const Mesh& mesh_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace rsibr
