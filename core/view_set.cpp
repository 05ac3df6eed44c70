#include "core/view_set.h"

#include "core/spherical_triangle.h"

extern "C" {
#include <libqhull_r/qhull_ra.h>
}

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>

namespace rsibr {
namespace {

constexpr double kTieEps = 1e-12;    // radians: how far outside an edge still counts as on it
constexpr double kPlanarEps = 1e-9;  // relative size below which a set is treated as planar

double det3(const Vec3& a, const Vec3& b, const Vec3& c) { return a.dot(b.cross(c)); }

// v / |v| for any finite non-zero v: rescaled first where |v|^2 would overflow or underflow.
Vec3 unit(const Vec3& v) {
  const double sq = v.squaredNorm();
  if (sq > 1e-290 && sq < 1e290) return v.normalized();
  return (v / v.cwiseAbs().maxCoeff()).normalized();
}
bool finite_nonzero(const Vec3& v) { return v.allFinite() && v.cwiseAbs().maxCoeff() > 0; }

// Canonical form of a counter-clockwise triangle: smallest index first, orientation kept.
std::array<int, 3> canonical(std::array<int, 3> t) {
  while (t[0] > t[1] || t[0] > t[2]) t = {t[1], t[2], t[0]};
  return t;
}

struct QhullFace {
  std::array<int, 3> v;
  Vec3 normal;
  double offset;
};

// Convex hull of points in general (non-planar) position, triangulated ('Qt').
std::vector<QhullFace> qhull_faces(const std::vector<Vec3>& pts) {
  std::vector<coordT> coords;
  coords.reserve(pts.size() * 3);
  for (const Vec3& p : pts) coords.insert(coords.end(), {p.x(), p.y(), p.z()});
  qhT qh_storage;
  qhT* qh = &qh_storage;
  FILE* errfile = std::tmpfile();
  QHULL_LIB_CHECK
  qh_zero(qh, errfile);
  char flags[] = "qhull Qt";
  const int status = qh_new_qhull(qh, 3, int(pts.size()), coords.data(), False, flags, nullptr, errfile);
  std::vector<QhullFace> faces;
  if (status == 0) {
    facetT* facet;
    vertexT *vertex, **vertexp;
    FORALLfacets {
      QhullFace f;
      int k = 0;
      FOREACHvertex_(facet->vertices) {
        if (k < 3) f.v[std::size_t(k)] = qh_pointid(qh, vertex->point);
        ++k;
      }
      if (k != 3) continue;
      f.normal = Vec3(facet->normal[0], facet->normal[1], facet->normal[2]);
      f.offset = facet->offset;
      faces.push_back(f);
    }
  }
  qh_freeqhull(qh, !qh_ALL);
  int curlong = 0, totlong = 0;
  qh_memfreeshort(qh, &curlong, &totlong);
  if (errfile) std::fclose(errfile);
  if (status != 0) throw std::runtime_error("view set: qhull failed to triangulate the views");
  return faces;
}

// p = alpha a + beta b for p on the great circle of a and b; weights alpha, beta normalised.
std::array<double, 2> arc_weights(const Vec3& p, const Vec3& a, const Vec3& b) {
  if (p == a) return {1, 0};
  if (p == b) return {0, 1};
  const Vec3 n = a.cross(b);
  const double da = std::max(0.0, det3(p, b, n)), db = std::max(0.0, det3(a, p, n));
  const double s = da + db;
  if (!(s > 0)) return a.dot(p) >= b.dot(p) ? std::array<double, 2>{1, 0} : std::array<double, 2>{0, 1};
  return {da / s, db / s};
}

}  // namespace

std::array<double, 3> triangle_weights(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c, Barycentric kind) {
  if (p == a) return {1, 0, 0};
  if (p == b) return {0, 1, 0};
  if (p == c) return {0, 0, 1};
  // Signed volumes decide which side of each edge p is on; negative means outside, clamp to 0.
  // Written with differences of nearby unit vectors (exact or nearly), so that they keep full
  // relative precision for tiny triangles (det(p,b,c) = det(p, b-p, c-p), and so on).
  const double da = det3(p, b - p, c - p), db = det3(a, p - a, c - a), dc = det3(a, b - a, p - a);
  std::array<double, 3> w{std::max(0.0, da), std::max(0.0, db), std::max(0.0, dc)};
  if (kind == Barycentric::SolidAngle) {
    if (w[0] > 0) w[0] = spherical_triangle_solid_angle(p, b, c);
    if (w[1] > 0) w[1] = spherical_triangle_solid_angle(a, p, c);
    if (w[2] > 0) w[2] = spherical_triangle_solid_angle(a, b, p);
  }
  const double s = w[0] + w[1] + w[2];
  if (!(s > 0) || !std::isfinite(s)) {
    // p far outside (or a degenerate triangle): the nearest vertex takes everything.
    const double ka = a.dot(p), kb = b.dot(p), kc = c.dot(p);
    if (ka >= kb && ka >= kc) return {1, 0, 0};
    return kb >= kc ? std::array<double, 3>{0, 1, 0} : std::array<double, 3>{0, 0, 1};
  }
  return {w[0] / s, w[1] / s, w[2] / s};
}

ViewSet::ViewSet(std::vector<Vec3> views) : views_(std::move(views)) {
  if (views_.empty()) throw std::invalid_argument("view set: no views");
  for (std::size_t i = 0; i < views_.size(); ++i) {
    const Vec3& v = views_[i];
    if (!finite_nonzero(v))
      throw std::invalid_argument("view set: view " + std::to_string(i) + " is zero or not finite");
    views_[i] = unit(v);
  }
  for (std::size_t i = 0; i < views_.size(); ++i)
    for (std::size_t j = i + 1; j < views_.size(); ++j)
      if (angle_between(views_[i], views_[j]) < 1e-9)
        throw std::invalid_argument("view set: views " + std::to_string(i) + " and " + std::to_string(j) + " coincide");
  triangulate();
}

void ViewSet::triangulate() {
  const int n = int(views_.size());
  if (n == 1) return;

  // Planarity: the smallest principal extent of the points, relative to the largest (a tiny
  // cluster of views is thin in absolute terms but is not planar: its hull is its triangulation).
  Vec3 centroid = Vec3::Zero();
  for (const Vec3& v : views_) centroid += v;
  centroid /= n;
  Mat3 cov = Mat3::Zero();
  for (const Vec3& v : views_) cov += (v - centroid) * (v - centroid).transpose();
  Eigen::SelfAdjointEigenSolver<Mat3> eig(cov / n);
  bool planar = n <= 3 || std::sqrt(std::max(0.0, eig.eigenvalues()(0))) <
                              kPlanarEps * std::sqrt(std::max(0.0, eig.eigenvalues()(2)));
  std::vector<QhullFace> faces;
  if (!planar) {
    try {
      faces = qhull_faces(views_);
    } catch (const std::runtime_error&) {
      planar = true;  // thinner than qhull can resolve in double precision: treat as planar
    }
  }

  std::vector<std::array<int, 3>> tris;
  if (!planar) {
    for (const QhullFace& f : faces) {
      if (!(f.offset < -kPlanarEps)) continue;  // origin on or beyond the face: a gap, not a triangle
      std::array<int, 3> t = f.v;
      const Vec3 &a = views_[std::size_t(t[0])], &b = views_[std::size_t(t[1])], &c = views_[std::size_t(t[2])];
      const double orient = (b - a).cross(c - a).dot(f.normal);
      if (std::abs(orient) < 1e-18) continue;  // zero-area piece of a triangulated coplanar facet
      if (orient < 0) std::swap(t[1], t[2]);
      tris.push_back(canonical(t));
    }
  } else {
    // All views on one plane: order them around its normal m.
    Vec3 m = eig.eigenvectors().col(0);
    if (n == 2) m = views_[0].cross(views_[1]);
    const double offset = m.dot(centroid);
    if (m.norm() > 0) m.normalize();
    const Vec3 e1 = (std::abs(m.x()) < 0.9 ? Vec3(1, 0, 0) : Vec3(0, 1, 0)).cross(m).normalized();
    const Vec3 e2 = m.cross(e1);
    std::vector<int> order(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) order[std::size_t(i)] = i;
    const Vec3 c0 = centroid - m.dot(centroid) * m;
    std::sort(order.begin(), order.end(), [&](int i, int j) {
      const Vec3 di = views_[std::size_t(i)] - c0, dj = views_[std::size_t(j)] - c0;
      const double ai = std::atan2(di.dot(e2), di.dot(e1)), aj = std::atan2(dj.dot(e2), dj.dot(e1));
      return ai != aj ? ai < aj : i < j;
    });
    if (n >= 3 && std::abs(offset) > kPlanarEps) {
      // A small circle: one convex polygon, fanned from its lowest index, facing away from the origin.
      std::rotate(order.begin(), std::min_element(order.begin(), order.end()), order.end());
      for (int i = 1; i + 1 < n; ++i) {
        std::array<int, 3> t{order[0], order[std::size_t(i)], order[std::size_t(i + 1)]};
        const Vec3 &a = views_[std::size_t(t[0])], &b = views_[std::size_t(t[1])], &c = views_[std::size_t(t[2])];
        if ((b - a).cross(c - a).dot(centroid) < 0) std::swap(t[1], t[2]);
        tris.push_back(canonical(t));
      }
    } else {
      // A great circle (or two views): no triangle; arcs join neighbours, never the long way round.
      const int arcs = n == 2 ? 1 : n;
      for (int i = 0; i < arcs; ++i) {
        const int a = order[std::size_t(i)], b = order[std::size_t((i + 1) % n)];
        if (angle_between(views_[std::size_t(a)], views_[std::size_t(b)]) < kPi - 1e-9 &&
            (n == 2 || det3(views_[std::size_t(a)], views_[std::size_t(b)], m) >= 0))
          boundary_.push_back({std::min(a, b), std::max(a, b), -1});
      }
    }
  }
  std::sort(tris.begin(), tris.end());
  triangles_ = tris;

  // Caps for quick rejection, and boundary arcs (edges not shared by two triangles).
  std::map<std::pair<int, int>, int> directed;
  for (std::size_t t = 0; t < triangles_.size(); ++t) {
    const auto& T = triangles_[t];
    const Vec3 &a = views_[std::size_t(T[0])], &b = views_[std::size_t(T[1])], &c = views_[std::size_t(T[2])];
    Vec3 centre = (b - a).cross(c - a).normalized();
    if (centre.dot(a) < 0) centre = -centre;
    cap_centre_.push_back(centre);
    cap_cos_.push_back(std::min({centre.dot(a), centre.dot(b), centre.dot(c)}) - 1e-9);
    for (int k = 0; k < 3; ++k) directed[{T[std::size_t(k)], T[std::size_t((k + 1) % 3)]}] = int(t);
  }
  for (const auto& [edge, t] : directed)
    if (!directed.count({edge.second, edge.first})) boundary_.push_back({edge.first, edge.second, t});
  surrounds_ = !triangles_.empty() && boundary_.empty();
}

ViewSet ViewSet::icosahedron() {
  const double phi = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Vec3> v;
  for (double s1 : {-1.0, 1.0})
    for (double s2 : {-1.0, 1.0}) {
      v.emplace_back(0, s1, s2 * phi);
      v.emplace_back(s1, s2 * phi, 0);
      v.emplace_back(s2 * phi, 0, s1);
    }
  return ViewSet(v);
}

ViewSet ViewSet::geodesic(int k) {
  if (k < 0 || k > 5) throw std::invalid_argument("view set: geodesic subdivision level must be 0..5");
  ViewSet set = icosahedron();
  for (int level = 0; level < k; ++level) {
    std::vector<Vec3> pts = set.views();
    std::map<std::pair<int, int>, int> midpoint;
    for (const auto& T : set.triangles())
      for (int e = 0; e < 3; ++e) {
        const int a = T[std::size_t(e)], b = T[std::size_t((e + 1) % 3)];
        const auto key = std::make_pair(std::min(a, b), std::max(a, b));
        if (midpoint.count(key)) continue;
        midpoint[key] = int(pts.size());
        pts.push_back((pts[std::size_t(a)] + pts[std::size_t(b)]).normalized());
      }
    set = ViewSet(pts);
  }
  return set;
}

ViewSet ViewSet::tetrahedron() {
  return ViewSet({Vec3(1, 1, 1).normalized(), Vec3(1, -1, -1).normalized(), Vec3(-1, 1, -1).normalized(),
                  Vec3(-1, -1, 1).normalized()});
}

ViewSet ViewSet::octahedron() {
  return ViewSet({Vec3(1, 0, 0), Vec3(-1, 0, 0), Vec3(0, 1, 0), Vec3(0, -1, 0), Vec3(0, 0, 1), Vec3(0, 0, -1)});
}

ViewSet ViewSet::fibonacci(int n) {
  if (n < 4) throw std::invalid_argument("fibonacci view set: need at least 4 views, got " + std::to_string(n));
  std::vector<Vec3> v;
  const double golden = kPi * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < n; ++i) {
    const double z = 1.0 - (2.0 * i + 1.0) / n, s = std::sqrt(std::max(0.0, 1.0 - z * z));
    v.emplace_back(s * std::cos(golden * i), s * std::sin(golden * i), z);
  }
  return ViewSet(v);
}

ViewSet ViewSet::named(const std::string& name) {
  if (name == "tetra" || name == "tetrahedron") return tetrahedron();
  if (name == "octa" || name == "octahedron") return octahedron();
  if (name.size() > 3 && name.rfind("fib", 0) == 0 && name.find_first_not_of("0123456789", 3) == std::string::npos &&
      name.size() < 9)
    return fibonacci(std::stoi(name.substr(3)));
  if (name == "icosa" || name == "icosahedron" || name == "12") return icosahedron();
  if (name == "42") return geodesic(1);
  if (name == "162") return geodesic(2);
  if (name == "642") return geodesic(3);
  std::ifstream in(name);
  if (!in)
    throw std::invalid_argument(name +
                                ": not a view set name (tetra, octa, icosa, 42, 162, 642, fibN) nor a readable file");
  std::vector<Vec3> views;
  std::string line;
  int lineno = 0;
  while (std::getline(in, line)) {
    ++lineno;
    const auto hash = line.find('#');
    if (hash != std::string::npos) line.resize(hash);
    if (line.find_first_not_of(" \t\r\f\v") == std::string::npos) continue;  // blank or comment line
    std::istringstream ls(line);
    double x, y, z;
    std::string rest;
    if (!(ls >> x >> y >> z) || (ls >> rest))
      throw std::invalid_argument(name + ":" + std::to_string(lineno) + ": expected three numbers 'x y z'");
    views.emplace_back(x, y, z);
  }
  try {
    return ViewSet(views);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(name + ": " + e.what());
  }
}

int ViewSet::nearest_view(const Vec3& dir) const {
  int best = 0;
  double best_dot = -2;
  for (std::size_t i = 0; i < views_.size(); ++i) {
    const double d = views_[i].dot(dir);
    if (d > best_dot) {
      best_dot = d;
      best = int(i);
    }
  }
  return best;
}

ViewWeights ViewSet::on_arc(const Vec3& p, const Arc& arc, Barycentric kind, double distance) const {
  const Vec3 &a = views_[std::size_t(arc.a)], &b = views_[std::size_t(arc.b)];
  ViewWeights out;
  out.inside = false;
  out.distance = distance;
  out.triangle = arc.triangle;
  // Closest point q of the arc to p.
  const Vec3 n = a.cross(b).normalized();
  Vec3 q = p - p.dot(n) * n;
  if (q.norm() < 1e-15) {
    q = a;
  } else {
    q.normalize();
    if (det3(a, q, n) < 0 || det3(q, b, n) < 0) q = a.dot(p) >= b.dot(p) ? a : b;
  }
  if (arc.triangle >= 0) {
    // The weights the triangle gives on its own edge, so they join those inside continuously.
    const auto& T = triangles_[std::size_t(arc.triangle)];
    const auto w =
        triangle_weights(q, views_[std::size_t(T[0])], views_[std::size_t(T[1])], views_[std::size_t(T[2])], kind);
    out.count = 3;
    out.views = T;
    out.weights = w;
  } else {
    const auto w = arc_weights(q, a, b);
    out.count = 2;
    out.views = {arc.a, arc.b, -1};
    out.weights = {w[0], w[1], 0};
  }
  return out;
}

ViewWeights ViewSet::locate(const Vec3& dir, Barycentric kind) const {
  if (!finite_nonzero(dir)) throw std::invalid_argument("view set: locate() needs a finite non-zero direction");
  const Vec3 p = unit(dir);
  ViewWeights out;
  if (views_.size() == 1) {
    out.count = 1;
    out.views = {0, -1, -1};
    out.weights = {1, 0, 0};
    out.distance = angle_between(p, views_[0]);
    out.inside = out.distance == 0;
    return out;
  }
  // The triangle containing p (within kTieEps of its edges), preferring the most interior.
  int best = -1;
  double best_score = -kTieEps;
  for (std::size_t t = 0; t < triangles_.size(); ++t) {
    if (cap_centre_[t].dot(p) < cap_cos_[t]) continue;
    const auto& T = triangles_[t];
    const Vec3 &a = views_[std::size_t(T[0])], &b = views_[std::size_t(T[1])], &c = views_[std::size_t(T[2])];
    // Signed angular distance (sine) of p from each edge's great circle; positive inside.
    const double s0 = det3(a, b, p) / a.cross(b).norm();
    const double s1 = det3(b, c, p) / b.cross(c).norm();
    const double s2 = det3(c, a, p) / c.cross(a).norm();
    const double score = std::min({s0, s1, s2});
    if (score > best_score || (best < 0 && score >= best_score)) {
      best_score = score;
      best = int(t);
    }
  }
  if (best >= 0) {
    const auto& T = triangles_[std::size_t(best)];
    out.count = 3;
    out.views = T;
    out.weights =
        triangle_weights(p, views_[std::size_t(T[0])], views_[std::size_t(T[1])], views_[std::size_t(T[2])], kind);
    out.triangle = best;
    out.inside = true;
    out.distance = 0;
    return out;
  }
  // Outside the covered region: the nearest boundary arc.
  int best_arc = -1;
  double best_dist = 0;
  for (std::size_t i = 0; i < boundary_.size(); ++i) {
    const Vec3 &a = views_[std::size_t(boundary_[i].a)], &b = views_[std::size_t(boundary_[i].b)];
    const Vec3 n = a.cross(b).normalized();
    Vec3 q = p - p.dot(n) * n;
    double d;
    if (q.norm() > 1e-15 && det3(a, q.normalized(), n) >= 0 && det3(q.normalized(), b, n) >= 0)
      d = angle_between(p, q);
    else
      d = std::min(angle_between(p, a), angle_between(p, b));
    if (best_arc < 0 || d < best_dist) {
      best_dist = d;
      best_arc = int(i);
    }
  }
  if (best_arc >= 0) return on_arc(p, boundary_[std::size_t(best_arc)], kind, best_dist);
  // No triangle and no usable arc (e.g. two antipodal views): the nearest view.
  const int v = nearest_view(p);
  out.count = 1;
  out.views = {v, -1, -1};
  out.weights = {1, 0, 0};
  out.distance = angle_between(p, views_[std::size_t(v)]);
  return out;
}

}  // namespace rsibr
