// Adaptive cubature over regions of the sphere of directions, for tests: independent of every
// sampler, so it can check pdfs and albedos.
//
// A region is a rectangle in (z = cos theta, phi) about +z; dw = dz dphi, so equal rectangles
// have equal solid angle. Each rectangle is integrated by a 5x5 Gauss-Legendre product rule and
// compared with the sum over its four quarters; quarters are refined recursively (tolerance
// halved per level, so a discontinuity along a curve still converges) until they agree or the
// depth limit is hit. Break lists split the rectangle first: put breaks on known
// discontinuities (e.g. z = -cos theta_o for visible-normal pdfs) and around narrow peaks.
#pragma once

#include "bake/shading_frame.h"
#include "core/vec.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

namespace rsibr::test {

struct Breaks {
  std::vector<double> z;    // extra z (cos theta) breakpoints
  std::vector<double> phi;  // extra phi breakpoints (radians, any range; wrapped to [0, 2pi))
};

struct QuadratureStats {
  long evaluations = 0;
  long unconverged = 0;  // rectangles accepted at the depth limit
};

namespace detail {

inline double magnitude(double x) { return std::abs(x); }
inline double magnitude(const Vec3& v) { return v.cwiseAbs().maxCoeff(); }

constexpr std::array<double, 5> kGlNode = {-0.9061798459386640, -0.5384693101056831, 0.0, 0.5384693101056831,
                                           0.9061798459386640};
constexpr std::array<double, 5> kGlWeight = {0.2369268850561891, 0.4786286704993665, 0.5688888888888889,
                                             0.4786286704993665, 0.2369268850561891};

template <class T, class F>
T gauss_rect(F& f, double z0, double z1, double p0, double p1, QuadratureStats& st) {
  const double hz = 0.5 * (z1 - z0), hp = 0.5 * (p1 - p0), cz = 0.5 * (z0 + z1), cp = 0.5 * (p0 + p1);
  T sum = T(f(Vec3(0, 0, 1)) * 0.0);
  ++st.evaluations;
  for (int i = 0; i < 5; ++i) {
    const double z = cz + hz * kGlNode[std::size_t(i)];
    for (int j = 0; j < 5; ++j) {
      const double phi = cp + hp * kGlNode[std::size_t(j)];
      sum += T(f(shading::spherical_direction(z, phi)) * (kGlWeight[std::size_t(i)] * kGlWeight[std::size_t(j)]));
    }
  }
  st.evaluations += 25;
  return T(sum * (hz * hp));
}

template <class T, class F>
T adapt(F& f, double z0, double z1, double p0, double p1, T whole, double tol, int depth, int min_depth, int max_depth,
        QuadratureStats& st) {
  const double zm = 0.5 * (z0 + z1), pm = 0.5 * (p0 + p1);
  const T q[4] = {gauss_rect<T>(f, z0, zm, p0, pm, st), gauss_rect<T>(f, zm, z1, p0, pm, st),
                  gauss_rect<T>(f, z0, zm, pm, p1, st), gauss_rect<T>(f, zm, z1, pm, p1, st)};
  const T sum = T(q[0] + q[1] + q[2] + q[3]);
  if (depth >= min_depth && magnitude(T(sum - whole)) <= tol) return sum;
  if (depth >= max_depth) {
    ++st.unconverged;
    return sum;
  }
  const double zs[3] = {z0, zm, z1}, ps[3] = {p0, pm, p1};
  T out = T(sum * 0.0);
  int k = 0;
  for (int b = 0; b < 2; ++b)
    for (int a = 0; a < 2; ++a, ++k) {
      // q is ordered (a, b) = (0,0), (1,0), (0,1), (1,1).
      out += adapt<T>(f, zs[a], zs[a + 1], ps[b], ps[b + 1], q[k], 0.5 * tol, depth + 1, min_depth, max_depth, st);
    }
  return out;
}

inline std::vector<double> cuts(double lo, double hi, std::vector<double> extra) {
  std::vector<double> v{lo, hi};
  for (double x : extra)
    if (x > lo && x < hi) v.push_back(x);
  std::sort(v.begin(), v.end());
  v.erase(std::unique(v.begin(), v.end(), [](double a, double b) { return b - a < 1e-15; }), v.end());
  return v;
}

}  // namespace detail

struct QuadratureOptions {
  double tol = 1e-7;  // absolute, for the whole rectangle (shared equally by its pieces)
  int min_depth = 1;
  int max_depth = 18;
};

// Integral of f(direction) over the rectangle [z0,z1] x [p0,p1] (solid angle measure).
template <class T, class F>
T integrate_rect(F&& f, double z0, double z1, double p0, double p1, const Breaks& breaks = {},
                 const QuadratureOptions& opt = {}, QuadratureStats* stats = nullptr) {
  QuadratureStats local;
  QuadratureStats& st = stats ? *stats : local;
  std::vector<double> phis;
  for (double p : breaks.phi) {
    const double w = std::fmod(std::fmod(p, 2 * kPi) + 2 * kPi, 2 * kPi);
    phis.push_back(w);
  }
  const auto zc = detail::cuts(z0, z1, breaks.z);
  const auto pc = detail::cuts(p0, p1, phis);
  const double tol = opt.tol / double((zc.size() - 1) * (pc.size() - 1));
  T total = T(f(Vec3(0, 0, 1)) * 0.0);
  for (std::size_t i = 0; i + 1 < zc.size(); ++i)
    for (std::size_t j = 0; j + 1 < pc.size(); ++j) {
      const T whole = detail::gauss_rect<T>(f, zc[i], zc[i + 1], pc[j], pc[j + 1], st);
      total += detail::adapt<T>(f, zc[i], zc[i + 1], pc[j], pc[j + 1], whole, tol, 1, opt.min_depth, opt.max_depth, st);
    }
  return total;
}

// Breaks that resolve peaks at the given unit directions (z and phi cuts at growing distances)
// and a near-pole/near-equator grading, plus a uniform base grid of nz x nphi.
inline Breaks peak_breaks(const std::vector<Vec3>& peaks, int nz = 32, int nphi = 16) {
  Breaks b;
  for (int i = 1; i < nz; ++i) b.z.push_back(-1.0 + 2.0 * i / nz);
  for (int i = 1; i < nphi; ++i) b.phi.push_back(2 * kPi * i / nphi);
  for (int k = 1; k <= 8; ++k) {
    b.z.push_back(1.0 - std::pow(10.0, -k));
    b.z.push_back(-1.0 + std::pow(10.0, -k));
    b.z.push_back(std::pow(10.0, -k));
    b.z.push_back(-std::pow(10.0, -k));
  }
  b.z.push_back(0.0);
  for (const Vec3& p : peaks) {
    const double phi = std::atan2(p.y(), p.x());
    for (double d : {1e-4, 1e-3, 3e-3, 1e-2, 3e-2, 0.1}) {
      b.z.push_back(p.z() - d);
      b.z.push_back(p.z() + d);
      b.phi.push_back(phi - d);
      b.phi.push_back(phi + d);
    }
    b.z.push_back(p.z());
    b.phi.push_back(phi);
  }
  return b;
}

// Integral of f over the part of the sphere with z in [z0, z1].
template <class T, class F>
T integrate_sphere(F&& f, const Breaks& breaks, double z0 = -1.0, double z1 = 1.0, const QuadratureOptions& opt = {},
                   QuadratureStats* stats = nullptr) {
  return integrate_rect<T>(f, z0, z1, 0.0, 2 * kPi, breaks, opt, stats);
}

}  // namespace rsibr::test
