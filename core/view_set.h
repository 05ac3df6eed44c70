// View sets: the unit view directions of a map set and their triangulation (docs/conventions.md, "View sets").
//
// Any set is triangulated by the convex hull of its unit view vectors (qhull), recomputed
// deterministically from the vectors alone. A hull face whose plane has the origin strictly on its
// inner side is a spherical triangle of the set; faces with the origin on or beyond their plane
// (the "gap" a set leaves when it does not surround the sphere) are not. Degenerate sets (1 view,
// 2 views, all views on one plane) are handled explicitly.
//
// Point location: a direction inside a spherical triangle gets that triangle (ties on shared
// edges and vertices go to the candidate whose nearest edge is farthest, then to the lowest
// triangle index: deterministic). A direction outside every triangle is projected to the nearest
// point of the covered region's boundary (or, for sets with no triangle, of the arcs between
// consecutive views) and gets the weights there; `inside` is false and `distance` says how far
// (radians) it was.
#pragma once

#include "core/vec.h"

#include <array>
#include <string>
#include <vector>

namespace rsibr {

// How the three weights of a spherical triangle (a,b,c) are computed for a direction p.
enum class Barycentric {
  // w_a : w_b : w_c = det(p,b,c) : det(a,p,c) : det(a,b,p) (central projection of p onto the
  // triangle's plane, then planar barycentrics). Continuous across every edge of any
  // triangulation: on edge (b,c) both neighbours give the same split. The default.
  Gnomonic,
  // The paper's: w_a : w_b : w_c = Omega(p,b,c) : Omega(a,p,c) : Omega(a,b,p), the solid angles of
  // the sub-triangles (computed with the stable atan2 formula, not the paper's acos dihedral
  // angles). Equals the areal definition exactly, but jumps across edges shared by triangles of
  // different shape: slightly where neighbours are nearly congruent, much more on arbitrary sets
  // (how much: docs/conventions.md, "Barycentric weights").
  SolidAngle,
};

// Weights of p in the spherical triangle (a,b,c) (unit vectors, counter-clockwise seen from
// outside). Non-negative, sum to 1, exactly (1,0,0) when p == a bitwise (likewise b, c), finite
// for every input including p on an edge or vertex; p slightly outside is clamped to the triangle.
std::array<double, 3> triangle_weights(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c,
                                       Barycentric kind = Barycentric::Gnomonic);

struct ViewWeights {
  int count = 0;                         // number of views used (1..3)
  std::array<int, 3> views{-1, -1, -1};  // indices into ViewSet::views()
  std::array<double, 3> weights{0, 0, 0};
  int triangle = -1;    // triangle index, or -1 (degenerate sets, boundary arcs)
  bool inside = false;  // p lies in a triangle of the set
  double distance = 0;  // radians from p to the covered region (0 inside)
};

class ViewSet {
 public:
  // Throws std::invalid_argument for empty sets, non-finite or zero vectors and views closer
  // than 1e-9 rad to another.
  explicit ViewSet(std::vector<Vec3> views);

  static ViewSet icosahedron();
  // Geodesic subdivision of the icosahedron: k = 0, 1, 2, 3 give 12, 42, 162, 642 views.
  static ViewSet geodesic(int k);
  // The 4 vertices of a regular tetrahedron ((+-1, +-1, +-1) with an even number of minus signs): the
  // fewest views that surround the sphere (for view-independent maps, e.g. albedo-normalised ones).
  static ViewSet tetrahedron();
  // The 6 axis directions.
  static ViewSet octahedron();
  // n >= 4 points of the Fibonacci sphere: z_i = 1 - (2i+1)/n, azimuth i * pi (3 - sqrt 5) about +Z.
  static ViewSet fibonacci(int n);
  // "tetra" / "octa" / "icosa" / "12" / "42" / "162" / "642" / "fibN" (N >= 4), or a text file with one
  // "x y z" per line ('#' comments).
  static ViewSet named(const std::string& name);

  const std::vector<Vec3>& views() const { return views_; }
  // Spherical triangles, each counter-clockwise seen from outside, sorted.
  const std::vector<std::array<int, 3>>& triangles() const { return triangles_; }
  // True when the triangles cover the whole sphere.
  bool surrounds() const { return surrounds_; }

  ViewWeights locate(const Vec3& dir, Barycentric kind = Barycentric::Gnomonic) const;
  // Index of the view nearest to dir (ties: lowest index).
  int nearest_view(const Vec3& dir) const;

 private:
  struct Arc {
    int a, b;      // view indices
    int triangle;  // triangle the arc belongs to, or -1 (arcs of a degenerate set)
  };
  void triangulate();
  ViewWeights on_arc(const Vec3& p, const Arc& arc, Barycentric kind, double distance) const;

  std::vector<Vec3> views_;
  std::vector<std::array<int, 3>> triangles_;
  std::vector<Vec3> cap_centre_;  // per triangle: circumcircle centre (unit) ...
  std::vector<double> cap_cos_;   // ... and cos of its angular radius, for quick rejection
  std::vector<Arc> boundary_;     // arcs bounding the covered region (or joining a degenerate set)
  bool surrounds_ = false;
};

}  // namespace rsibr
