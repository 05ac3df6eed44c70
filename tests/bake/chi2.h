// A reusable chi-square goodness-of-fit test for direction samplers (after Mitsuba 3's
// chi2.py). The sphere is cut into n_theta x n_phi bins of equal solid angle (equal steps in
// cos theta and phi about +z); N samples are histogrammed; the expected count of each bin is N
// times the integral of the claimed pdf over it (adaptive cubature, tests/bake/sphere_quadrature.h);
// failed samples form one more cell whose expectation is N (1 - integral of the pdf). Cells
// expecting fewer than `min_expected` samples are pooled. A sample at a direction where the
// pdf is 0 fails the test outright.
#pragma once

#include "tests/bake/sphere_quadrature.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace rsibr::test {

// Regularised upper incomplete gamma Q(a, x) (series below a+1, Lentz continued fraction above).
inline double gamma_q(double a, double x) {
  if (x <= 0) return 1.0;
  const double gln = std::lgamma(a);
  if (x < a + 1.0) {
    double ap = a, sum = 1.0 / a, del = sum;
    for (int n = 0; n < 100000; ++n) {
      ap += 1.0;
      del *= x / ap;
      sum += del;
      if (std::abs(del) < std::abs(sum) * 1e-15) break;
    }
    return std::max(0.0, 1.0 - sum * std::exp(-x + a * std::log(x) - gln));
  }
  const double fpmin = 1e-300;
  double b = x + 1.0 - a, c = 1.0 / fpmin, d = 1.0 / b, h = d;
  for (int i = 1; i < 100000; ++i) {
    const double an = -i * (i - a);
    b += 2.0;
    d = an * d + b;
    if (std::abs(d) < fpmin) d = fpmin;
    c = b + an / c;
    if (std::abs(c) < fpmin) c = fpmin;
    d = 1.0 / d;
    const double del = d * c;
    h *= del;
    if (std::abs(del - 1.0) < 1e-15) break;
  }
  return std::exp(-x + a * std::log(x) - gln) * h;
}

// P(chi^2_dof >= x).
inline double chi2_survival(double x, int dof) { return gamma_q(0.5 * dof, 0.5 * x); }

// Per-test significance that keeps the family-wise rate at `alpha` over n tests (Sidak).
inline double sidak(double alpha, int n) { return 1.0 - std::pow(1.0 - alpha, 1.0 / n); }

struct Chi2Options {
  int n_theta = 30;
  int n_phi = 60;
  long samples = 300000;
  std::uint64_t seed = 1;
  double min_expected = 5.0;
  double bin_tol = 1e-8;  // absolute quadrature tolerance per bin (pdf integral)
  Breaks breaks;          // discontinuities of the pdf (z, phi), passed to every bin
};

struct Chi2Result {
  double chi2 = 0, p_value = 0;
  int dof = 0;
  int cells = 0;
  double pdf_integral = 0;  // integral of the pdf over the sphere (sum of the bins)
  long failed = 0;          // samples the sampler did not produce
  std::string error;        // a sample where the pdf is 0, or a pdf integral above 1
  std::string summary() const {
    std::ostringstream s;
    s << "chi2 = " << chi2 << ", dof = " << dof << ", p = " << p_value << ", pdf integral = " << pdf_integral
      << ", failed = " << failed << (error.empty() ? "" : ", error: " + error);
    return s.str();
  }
};

// Uniform double in [0,1) from 53 random bits (the same on every platform, unlike the
// standard distributions).
inline double canonical(std::mt19937_64& rng) { return double(rng() >> 11) * 0x1.0p-53; }

// One proposal of a sampler: the direction and, when the sampler reports it, pdf(w) (the
// harness evaluates pdf(w) itself when pdf < 0). Samples where it is 0 are errors.
struct DirectionSample {
  Vec3 w;
  double pdf = -1;
};

// sample: Vec2 u -> std::optional<DirectionSample> (nullopt: no direction produced);
// pdf: Vec3 -> double (solid angle density over the sphere).
template <class SampleFn, class PdfFn>
Chi2Result chi2_test(SampleFn&& sample, PdfFn&& pdf, const Chi2Options& opt) {
  const int nt = opt.n_theta, np = opt.n_phi, nb = nt * np;
  Chi2Result r;
  // Samples in fixed chunks, each with its own generator seeded from (seed, chunk): the
  // histogram does not depend on the number of threads.
  const long chunk = 65536;
  const long n_chunks = (opt.samples + chunk - 1) / chunk;
  struct Partial {
    std::vector<double> observed;
    long failed = 0;
    std::string error;
  };
  std::vector<Partial> parts(static_cast<std::size_t>(n_chunks));
  tbb::parallel_for(long(0), n_chunks, [&](long c) {
    Partial& part = parts[std::size_t(c)];
    part.observed.assign(std::size_t(nb), 0.0);
    std::seed_seq seq{std::uint64_t(opt.seed), std::uint64_t(c)};
    std::mt19937_64 rng(seq);
    const long end = std::min(opt.samples, (c + 1) * chunk);
    for (long i = c * chunk; i < end; ++i) {
      const double u1 = canonical(rng), u2 = canonical(rng);
      const std::optional<DirectionSample> w = sample(Vec2(u1, u2));
      if (!w || !w->w.allFinite() || w->w.isZero()) {
        ++part.failed;
        continue;
      }
      const Vec3 d = w->w.normalized();
      const double p = w->pdf >= 0 ? w->pdf : pdf(d);
      if (part.error.empty() && !(p > 0)) {
        std::ostringstream s;
        s << "sampled (" << d.transpose() << ") where the pdf is " << p;
        part.error = s.str();
      }
      double phi = std::atan2(d.y(), d.x());
      if (phi < 0) phi += 2 * kPi;
      const int it = std::clamp(int((d.z() + 1.0) * 0.5 * nt), 0, nt - 1);
      const int ip = std::clamp(int(phi / (2 * kPi) * np), 0, np - 1);
      part.observed[std::size_t(it * np + ip)] += 1.0;
    }
  });
  std::vector<double> observed(std::size_t(nb), 0.0);
  for (const Partial& part : parts) {
    for (int b = 0; b < nb; ++b) observed[std::size_t(b)] += part.observed[std::size_t(b)];
    r.failed += part.failed;
    if (r.error.empty()) r.error = part.error;
  }

  std::vector<double> integral(std::size_t(nb), 0.0);
  tbb::parallel_for(0, nb, [&](int b) {
    const int it = b / np, ip = b % np;
    const double z0 = -1.0 + 2.0 * it / nt, z1 = -1.0 + 2.0 * (it + 1) / nt;
    const double p0 = 2 * kPi * ip / np, p1 = 2 * kPi * (ip + 1) / np;
    QuadratureOptions q;
    q.tol = opt.bin_tol;
    q.min_depth = 1;
    integral[std::size_t(b)] = integrate_rect<double>(pdf, z0, z1, p0, p1, opt.breaks, q);
  });
  r.pdf_integral = std::accumulate(integral.begin(), integral.end(), 0.0);

  struct Cell {
    double expected, observed;
  };
  std::vector<Cell> cells;
  for (int b = 0; b < nb; ++b) {
    cells.push_back({integral[std::size_t(b)] * double(opt.samples), observed[std::size_t(b)]});
  }
  if (r.pdf_integral > 1.0 + 1e-3 && r.error.empty()) r.error = "pdf integrates to more than 1";
  cells.push_back({std::max(0.0, 1.0 - r.pdf_integral) * double(opt.samples), double(r.failed)});

  // Pool the cells that expect too few samples (smallest first) into one.
  std::sort(cells.begin(), cells.end(), [](const Cell& a, const Cell& b) { return a.expected < b.expected; });
  Cell pool{0, 0};
  std::vector<Cell> kept;
  for (const Cell& c : cells) {
    if (c.expected < opt.min_expected) {
      pool.expected += c.expected;
      pool.observed += c.observed;
    } else {
      kept.push_back(c);
    }
  }
  if (pool.expected > 0 || pool.observed > 0) {
    if (pool.expected < opt.min_expected && !kept.empty()) {
      kept.front().expected += pool.expected;  // the smallest kept cell absorbs a thin pool
      kept.front().observed += pool.observed;
    } else {
      kept.push_back(pool);
    }
  }
  for (const Cell& c : kept) {
    if (c.expected > 0) {
      r.chi2 += (c.observed - c.expected) * (c.observed - c.expected) / c.expected;
    } else if (c.observed > 0) {
      r.chi2 = std::numeric_limits<double>::infinity();
    }
  }
  r.cells = int(kept.size());
  r.dof = std::max(1, r.cells - 1);
  r.p_value = chi2_survival(r.chi2, r.dof);
  return r;
}

}  // namespace rsibr::test
