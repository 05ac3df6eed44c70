#include "lights/source_recovery.h"

#include "bake/bright_texels.h"
#include "bake/integrator.h"
#include "bake/reference_integrator.h"
#include "bake/shading_frame.h"
#include "core/resample.h"
#include "core/parallel.h"
#include "core/sphere_map.h"
#include "hdr/nnls.h"
#include "lights/grey_source_cost.h"

#include <ceres/ceres.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <map>
#include <memory>
#include <sstream>
#include <stdexcept>

namespace rsibr {

namespace {

// One trusted texel of a captured ball map (the grey residual's fields, lights/grey_source_cost.h,
// and the glossy ones).
struct Texel : GreyObservation {
  Vec3 v;                      // world view direction (glossy)
  int ball = 0;                // index over grey then glossy balls
  int view = 0;                // index over distinct image names
  const Brdf* brdf = nullptr;  // glossy only
  Vec3 mirror = Vec3::Zero();  // glossy: the mirror direction of v about n
  double lobe = 0;             // glossy: the lobe's width (rad, bake/brdf.h), 0 for a normal lobe
  long count = 1;              // the map's texels it stands for (a grey ball's sub-grid, stride^2)
};

using Frame = SourceFrame;

Vec3 direction_of(const Frame& f, const double* x) { return source_direction(f, x); }

// The glossy ball's kernel: the mean over the cap of eval (cosine included), per channel.
Vec3 glossy_kernel(const Texel& t, const Vec3& d, double rho) {
  // A mirror lobe far from the disc (more than 4 lobe widths past its edge): its tail, below 1e-3
  // of the highlight for the BRDFs of bake/, is left out.
  if (t.lobe > 0 && angle_between(t.mirror, d) > rho + 4 * t.lobe) return Vec3::Zero();
  const shading::Frame frame = shading::Frame::around(t.n);
  const Vec3 wo = frame.to_local(t.v);
  if (!(wo.z() > 0)) return Vec3::Zero();
  const double lobe = std::max(t.lobe > 0 ? t.lobe : t.brdf->lobe_width(wo), 1e-4);
  const int rings = std::clamp(int(std::ceil(2 * rho / lobe)), 1, 4);
  const std::vector<Vec3> pts = light_kernels::cap_points(d, rho, rings);
  Vec3 sum = Vec3::Zero();
  for (const Vec3& w : pts) {
    const Vec3 wi = frame.to_local(w);
    if (wi.z() > 0) sum += t.brdf->eval(wo, wi);
  }
  return sum / double(pts.size());
}

// Per channel kernel of one source at one texel (what P multiplies).
Vec3 kernel(const Texel& t, const Vec3& d, double rho) {
  if (t.brdf) return glossy_kernel(t, d, rho);
  return t.gain * light_kernels::mean_clamped_cosine(t.n.dot(d), rho);
}

struct GlossyCost {
  const Texel* t;
  const std::vector<Frame>* frames;
  bool operator()(double const* const* x, double* r) const {
    Vec3 m = t->known;
    for (std::size_t s = 0; s < frames->size(); ++s) {
      const Vec3 k = glossy_kernel(*t, direction_of((*frames)[s], x[s]), std::max(x[s][5], 0.0));
      for (int ch = 0; ch < 3; ++ch) m[ch] += x[s][2 + ch] * k[ch];
    }
    for (int ch = 0; ch < 3; ++ch) r[ch] = t->sqrt_w * t->inv_scale[ch] * (t->obs[ch] - m[ch]);
    return true;
  }
};

// The model's residual vector (3 per texel) at parameters x.
void residuals(const std::vector<Texel>& texels, const std::vector<Frame>& frames,
               const std::vector<std::array<double, kSourceBlock>>& x, std::vector<double>* out) {
  out->assign(texels.size() * 3, 0.0);
  std::vector<Vec3> dirs;
  for (std::size_t s = 0; s < frames.size(); ++s) dirs.push_back(direction_of(frames[s], x[s].data()));
  parallel_for_rows(int(texels.size()), [&](int i) {
    const Texel& t = texels[std::size_t(i)];
    Vec3 m = t.known;
    for (std::size_t s = 0; s < frames.size(); ++s)
      m += kernel(t, dirs[s], x[s][5]).cwiseProduct(Vec3(x[s][2], x[s][3], x[s][4]));
    // Per map texel: a sub-grid texel's weight for the texels it stands for is left out.
    for (int ch = 0; ch < 3; ++ch)
      (*out)[3 * std::size_t(i) + ch] = t.sqrt_w / t.stride * t.inv_scale[ch] * (t.obs[ch] - m[ch]);
  });
}

double mad_sigma(const std::vector<double>& r) {
  if (r.empty()) return 0;
  std::vector<double> a(r.size());
  for (std::size_t i = 0; i < r.size(); ++i) a[i] = std::abs(r[i]);
  std::nth_element(a.begin(), a.begin() + long(a.size() / 2), a.end());
  return 1.4826 * a[a.size() / 2];
}

// Powers by non-negative least squares at fixed directions and radii, per channel, iteratively
// reweighted for the Huber loss of scale `delta` on each texel's residual norm (delta <= 0: plain
// least squares). `use` selects the texels (empty: all).
void solve_powers(const std::vector<Texel>& texels, const std::vector<Frame>& frames,
                  std::vector<std::array<double, kSourceBlock>>& x, double delta, const std::vector<char>& use) {
  const int S = int(frames.size());
  if (S == 0) return;
  std::vector<Vec3> dirs;
  for (int s = 0; s < S; ++s) dirs.push_back(direction_of(frames[std::size_t(s)], x[std::size_t(s)].data()));
  std::vector<std::vector<Vec3>> k(texels.size(), std::vector<Vec3>(std::size_t(S)));
  parallel_for_rows(int(texels.size()), [&](int i) {
    for (int s = 0; s < S; ++s)
      k[std::size_t(i)][std::size_t(s)] = kernel(texels[std::size_t(i)], dirs[std::size_t(s)], x[std::size_t(s)][5]);
  });
  std::vector<double> h(texels.size(), 1.0);
  const int rounds = delta > 0 ? 6 : 1;
  for (int round = 0; round < rounds; ++round) {
    for (int ch = 0; ch < 3; ++ch) {
      Eigen::MatrixXd Q = Eigen::MatrixXd::Zero(S, S);
      Eigen::VectorXd p = Eigen::VectorXd::Zero(S);
      for (std::size_t i = 0; i < texels.size(); ++i) {
        if (!use.empty() && !use[i]) continue;
        const Texel& t = texels[i];
        const double a = t.sqrt_w * t.inv_scale[ch];
        const double b = a * (t.obs[ch] - t.known[ch]);
        Eigen::VectorXd row(S);
        for (int s = 0; s < S; ++s) row(s) = a * k[i][std::size_t(s)][ch];
        Q.noalias() += h[i] * row * row.transpose();
        p.noalias() += h[i] * b * row;
      }
      // Scale to unit diagonal (the powers span decades), solve, scale back.
      Eigen::VectorXd scale(S);
      for (int s = 0; s < S; ++s) scale(s) = Q(s, s) > 0 ? 1 / std::sqrt(Q(s, s)) : 0;
      const Eigen::MatrixXd Qs = scale.asDiagonal() * Q * scale.asDiagonal();
      const Eigen::VectorXd z = nnls_gram(Qs, scale.cwiseProduct(p));
      for (int s = 0; s < S; ++s) x[std::size_t(s)][2 + ch] = std::isfinite(z(s) * scale(s)) ? z(s) * scale(s) : 0;
    }
    if (delta <= 0) break;
    for (std::size_t i = 0; i < texels.size(); ++i) {
      const Texel& t = texels[i];
      Vec3 m = t.known;
      for (int s = 0; s < S; ++s)
        m += k[i][std::size_t(s)].cwiseProduct(Vec3(x[std::size_t(s)][2], x[std::size_t(s)][3], x[std::size_t(s)][4]));
      const double norm = (t.sqrt_w * t.inv_scale.cwiseProduct(t.obs - m)).norm();
      h[i] = norm <= delta * t.stride ? 1.0 : delta * t.stride / norm;
    }
  }
}

struct Fit {
  std::vector<std::array<double, kSourceBlock>> x;
  std::vector<Eigen::Matrix<double, kSourceBlock, kSourceBlock>> covariance;  // scaled by the residual variance
  bool covariance_ok = false;
};

// The joint Ceres refinement from x (directions within their bounds, P >= 0, rho when fitted).
Fit refine(const std::vector<Texel>& texels, const std::vector<Frame>& frames,
           std::vector<std::array<double, kSourceBlock>> x, double delta, bool move_directions, bool fit_radius,
           bool want_covariance, const std::vector<char>& use, int iterations = 50) {
  Fit fit;
  const int S = int(frames.size());
  ceres::Problem::Options po;
  ceres::Problem problem(po);
  std::vector<double*> blocks;
  for (int s = 0; s < S; ++s) blocks.push_back(x[std::size_t(s)].data());
  long used = 0;
  // A glossy texel whose mirror direction lies more than two lobe widths beyond the reach of every
  // source (its region and largest radius) sees only the lobe's tail of it: left out of the
  // problem (most of a glossy ball, and most of the cost); the linear solves keep it.
  auto reachable = [&](const Texel& t) {
    if (!t.brdf || !(t.lobe > 0)) return true;
    for (const Frame& f : frames)
      if (angle_between(t.mirror, f.d0) <= f.max_radius + f.max_radius + 2 * t.lobe) return true;
    return false;
  };
  // The grey texels in one block (lights/grey_source_cost.h: Huber per texel inside it); each
  // glossy texel its own, numerically differentiated.
  std::vector<const GreyObservation*> grey;
  for (std::size_t i = 0; i < texels.size(); ++i) {
    if ((!use.empty() && !use[i]) || !reachable(texels[i])) continue;
    ++used;
    if (!texels[i].brdf) {
      grey.push_back(&texels[i]);
      continue;
    }
    auto* c = new ceres::DynamicNumericDiffCostFunction<GlossyCost>(new GlossyCost{&texels[i], &frames});
    for (int s = 0; s < S; ++s) c->AddParameterBlock(kSourceBlock);
    c->SetNumResiduals(3);
    problem.AddResidualBlock(c, delta > 0 ? new ceres::HuberLoss(delta) : nullptr, blocks);
  }
  if (!grey.empty()) problem.AddResidualBlock(new GreySourceCost(std::move(grey), &frames, delta), nullptr, blocks);
  if (used == 0) {
    fit.x = x;
    return fit;
  }
  for (int s = 0; s < S; ++s) {
    const Frame& f = frames[std::size_t(s)];
    double* b = blocks[std::size_t(s)];
    std::vector<int> constant;
    if (!move_directions) constant = {0, 1};
    if (!fit_radius) constant.push_back(5);
    if (!constant.empty()) problem.SetManifold(b, new ceres::SubsetManifold(kSourceBlock, constant));
    if (move_directions)
      for (int k = 0; k < 2; ++k)
        problem.SetParameterLowerBound(b, k, -f.bound), problem.SetParameterUpperBound(b, k, f.bound);
    for (int k = 2; k < 5; ++k) problem.SetParameterLowerBound(b, k, 0.0);
    if (fit_radius) {
      problem.SetParameterLowerBound(b, 5, 1e-4);
      problem.SetParameterUpperBound(b, 5, std::max(f.max_radius, 2e-4));
    }
  }
  ceres::Solver::Options so;
  so.linear_solver_type = ceres::DENSE_NORMAL_CHOLESKY;
  so.max_num_iterations = iterations;
  so.function_tolerance = 1e-10;
  so.parameter_tolerance = 1e-10;
  so.num_threads = 1;  // deterministic
  ceres::Solver::Summary summary;
  ceres::Solve(so, &problem, &summary);
  fit.x = x;
  if (!want_covariance) return fit;
  ceres::Covariance::Options co;
  co.algorithm_type = ceres::DENSE_SVD;
  co.null_space_rank = -1;  // a source the balls cannot see at all: pseudo-inverse instead of failure
  co.num_threads = 1;
  ceres::Covariance cov(co);
  std::vector<std::pair<const double*, const double*>> pairs;
  for (int s = 0; s < S; ++s) pairs.emplace_back(blocks[std::size_t(s)], blocks[std::size_t(s)]);
  // The residuals are in units of their own sigma only after dividing by it: scale by the
  // variance of the (robustified) residuals per degree of freedom.
  const double dof =
      std::max(1.0, 3.0 * double(used) - double(S) * (3 + (move_directions ? 2 : 0) + (fit_radius ? 1 : 0)));
  // The model's errors (the probe's known part, the extraction) are smooth over a ball, so the
  // texels of one ball in one view are not independent: a grey ball's shading is band-limited to
  // about 9 spherical-harmonic coefficients (the clamped cosine keeps ~99% of its energy in
  // orders 0-2), a glossy ball's to about 36 (orders 0-5). The covariance is inflated by the
  // texel count over that effective count of independent observations.
  std::map<std::pair<int, int>, std::pair<long, bool>> group;  // (ball, view) -> (texels, glossy)
  for (std::size_t i = 0; i < texels.size(); ++i)
    if ((use.empty() || use[i]) && reachable(texels[i])) {
      auto& g = group[{texels[i].ball, texels[i].view}];
      ++g.first;
      g.second = texels[i].brdf != nullptr;
    }
  double effective = 0;
  for (const auto& [key, g] : group) effective += std::min<double>(double(g.first), g.second ? 36.0 : 9.0);
  const double variance = 2 * summary.final_cost / dof * (effective > 0 ? double(used) / effective : 1.0);
  if (cov.Compute(pairs, &problem)) {
    fit.covariance_ok = true;
    for (int s = 0; s < S; ++s) {
      Eigen::Matrix<double, kSourceBlock, kSourceBlock, Eigen::RowMajor> c;
      cov.GetCovarianceBlock(blocks[std::size_t(s)], blocks[std::size_t(s)], c.data());
      fit.covariance.push_back(variance * c);
    }
  }
  return fit;
}

std::string degrees(double rad) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(1) << rad * 180 / kPi;
  return s.str();
}

std::string describe(const ClippedRegion& g) {
  const Vec3& d = g.direction;
  std::ostringstream s;
  s << "the clipped region at azimuth " << degrees(std::atan2(d.x(), d.z())) << ", elevation "
    << degrees(std::asin(std::clamp(d.y(), -1.0, 1.0))) << " degrees (" << std::setprecision(3) << g.solid_angle
    << " sr)";
  return s.str();
}

// The known part's irradiance at any normal, by quadrature over nodes (direction, L Omega): its
// bright texels (bake/bright_texels.h: >= 10 x the mean) at full resolution, so an unclipped lamp
// keeps its place, and the rest area-resampled (core/resample.h) to at most `width` texels wide.
// Stored as arrays so that the sum over nodes vectorises.
struct KnownIrradiance {
  std::vector<double> x, y, z, r, g, b;
  KnownIrradiance(const EnvMap& known, int width) {
    const EnvironmentSplit split = split_bright_texels(known);
    ResampleOptions ro;
    ro.supersampling = 1;  // plain area sampling: the bright texels are split off
    ro.energy_tolerance = 0;
    std::vector<ReferenceIntegrator::Texel> nodes = ReferenceIntegrator::texels_of(
        split.remainder.layout.width() <= width
            ? split.remainder
            : resample(split.remainder, Layout(LayoutKind::LatLong, width, std::max(2, width / 2)), ro));
    const int W = known.layout.width();
    for (const BrightTexel& t : split.bright)
      nodes.push_back(
          {known.layout.texel_direction(int(t.texel % W), int(t.texel / W))->normalized(), t.radiance * t.solid_angle});
    for (const auto& q : nodes) {
      x.push_back(q.dir.x()), y.push_back(q.dir.y()), z.push_back(q.dir.z());
      r.push_back(q.radiance.x()), g.push_back(q.radiance.y()), b.push_back(q.radiance.z());
    }
  }
  Vec3 operator()(const Vec3& n) const {
    double er = 0, eg = 0, eb = 0;
    for (std::size_t i = 0; i < x.size(); ++i) {
      const double c = std::max(0.0, n.x() * x[i] + n.y() * y[i] + n.z() * z[i]);
      er += c * r[i], eg += c * g[i], eb += c * b[i];
    }
    return Vec3(er, eg, eb);
  }
};

// The balls' trusted texels, each with the known part's prediction, and the names they index.
struct TrustedTexels {
  std::vector<Texel> texels;
  std::vector<std::string> view_names;  // distinct image names (MapView::image, else view.N)
  std::vector<std::string> ball_names, ball_kinds;
};

// One ball's maps added: every texel with confidence > 0 and finite radiance inside the disc; a
// grey ball's known part is albedo / pi times the known irradiance at its normal, a glossy ball's
// the FIS bake of its BRDF under the known part (made once, on the first glossy ball). Residuals
// are relative, with a floor of 5% of the ball's median value per channel.
void add_ball_texels(TrustedTexels& all, const std::string& name, const MapSet& maps, const Vec3& albedo,
                     const Brdf* brdf, const EnvMap& known, const KnownIrradiance& irradiance,
                     std::unique_ptr<Integrator>& fis, const SourceRecoveryOptions& options) {
  const int ball = int(all.ball_names.size());
  all.ball_names.push_back(name);
  all.ball_kinds.push_back(brdf ? "glossy" : "grey");
  std::map<std::string, int> view_index;
  for (std::size_t v = 0; v < all.view_names.size(); ++v) view_index[all.view_names[v]] = int(v);
  std::vector<Texel> mine;
  for (std::size_t v = 0; v < maps.views.size(); ++v) {
    const MapView& mv = maps.views[v];
    if (mv.confidence.empty() || mv.rgb.type() != CV_32FC3)
      throw std::invalid_argument("sources: " + name + " view." + std::to_string(v) +
                                  " has no confidence (not captured)");
    const std::string image = !mv.image.empty() ? mv.image : "view." + std::to_string(v);
    const auto [it, fresh] = view_index.emplace(image, int(all.view_names.size()));
    if (fresh) all.view_names.push_back(image);
    cv::Mat glossy_known;
    if (brdf) {
      if (!fis) fis = make_integrator("fis", known);
      IntegratorOptions io;
      io.samples = options.glossy_samples;
      io.seed = options.seed;
      glossy_known = fis->radiance_map(*brdf, mv.view, mv.world_from_view, mv.rgb.cols, io);
    }
    const int W = mv.rgb.cols, H = mv.rgb.rows;
    auto trusted = [&](int r, int c) {
      const float conf = mv.confidence.at<float>(r, c);
      const cv::Vec3f o = mv.rgb.at<cv::Vec3f>(r, c);
      return conf > 0 && std::isfinite(conf) && std::isfinite(o[0]) && std::isfinite(o[1]) && std::isfinite(o[2]) &&
             sphere_map::disc_from_pixel(Vec2(c, r), W, H).squaredNorm() < 1;
    };
    // A grey ball's shading is smooth (a clamped cosine of the sources, band-limited sky light): a
    // regular sub-grid of at most texels_per_view trusted texels fits it as well as every texel, at
    // a cost that does not grow with the photos' resolution. Each stands for stride^2 texels (its
    // weight and its count), so the fit's objective and the thresholds stay those of the map.
    int stride = 1;
    if (!brdf && options.texels_per_view > 0) {
      long n = 0;
      for (int r = 0; r < H; ++r)
        for (int c = 0; c < W; ++c) n += trusted(r, c);
      while (n > long(options.texels_per_view) * stride * stride) ++stride;
    }
    std::vector<std::vector<Texel>> rows(static_cast<std::size_t>(H));
    parallel_for_rows(H, [&](int r) {
      if (r % stride) return;
      for (int c = 0; c < W; c += stride) {
        if (!trusted(r, c)) continue;
        const float conf = mv.confidence.at<float>(r, c);
        const cv::Vec3f o = mv.rgb.at<cv::Vec3f>(r, c);
        const Vec2 xy = sphere_map::disc_from_pixel(Vec2(c, r), W, H);
        Texel t;
        t.n = (mv.world_from_view * sphere_map::g_normal(xy)).normalized();
        t.v = mv.view.normalized();
        t.obs = Vec3(std::max(0.f, o[0]), std::max(0.f, o[1]), std::max(0.f, o[2]));
        t.sqrt_w = std::sqrt(double(conf)) * stride;
        t.count = long(stride) * stride;
        t.stride = stride;
        t.ball = ball;
        t.view = it->second;
        if (brdf) {
          const cv::Vec3f g = glossy_known.at<cv::Vec3f>(r, c);
          t.known = Vec3(g[0], g[1], g[2]);
          t.gain = Vec3::Ones();
          t.brdf = brdf;
          t.mirror = 2 * t.n.dot(t.v) * t.n - t.v;
          if (brdf->central_direction() == CentralDirection::Mirror) {
            t.lobe = brdf->lobe_width(shading::Frame::around(t.n).to_local(t.v));
          }
        } else {
          t.gain = albedo / kPi;
          t.known = t.gain.cwiseProduct(irradiance(t.n));
        }
        rows[std::size_t(r)].push_back(t);
      }
    });
    for (auto& row : rows) mine.insert(mine.end(), row.begin(), row.end());
  }
  Vec3 floor = Vec3::Zero();
  for (int ch = 0; ch < 3 && !mine.empty(); ++ch) {
    std::vector<double> vals;
    for (const Texel& t : mine) vals.push_back(t.obs[ch]);
    std::nth_element(vals.begin(), vals.begin() + long(vals.size() / 2), vals.end());
    floor[ch] = std::max(0.05 * vals[vals.size() / 2], 1e-30);
  }
  for (Texel& t : mine)
    for (int ch = 0; ch < 3; ++ch) t.inv_scale[ch] = 1 / std::max(t.obs[ch], floor[ch]);
  all.texels.insert(all.texels.end(), mine.begin(), mine.end());
}

// The regions the balls can constrain (at most max_sources, each lighting at least min_lit_texels
// trusted texels), in order; the others are added to `out` as unrecovered, with why.
std::vector<int> constrained_regions(const std::vector<ClippedRegion>& regions, const std::vector<Texel>& texels,
                                     const SourceRecoveryOptions& options, SourceRecovery& out) {
  std::vector<int> chosen;
  for (std::size_t ri = 0; ri < regions.size(); ++ri) {
    const ClippedRegion& g = regions[ri];
    if (int(chosen.size()) >= options.max_sources) {
      out.unrecovered.push_back(int(ri));
      out.notes.push_back(describe(g) + ": not recovered (only the " + std::to_string(options.max_sources) +
                          " regions with the most clipped light are)");
      continue;
    }
    long lit = 0;
    for (const Texel& t : texels)
      if (light_kernels::mean_clamped_cosine(t.n.dot(g.direction), 0.0) > options.min_lit_kernel) lit += t.count;
    if (lit < options.min_lit_texels) {
      out.unrecovered.push_back(int(ri));
      out.notes.push_back(describe(g) + ": not recovered: " +
                          (texels.empty()
                               ? std::string("no grey or glossy ball with trusted texels")
                               : "the grey and glossy balls have " + std::to_string(lit) +
                                     " trusted texel(s) it lights (at least " + std::to_string(options.min_lit_texels) +
                                     " needed: the ball is missing, clipped or hidden there)") +
                          "; the probe keeps its lower bound");
      continue;
    }
    chosen.push_back(int(ri));
  }
  return chosen;
}

// The model M = K + sum_s P_s G_s at a texel (params: one block per source).
Vec3 model_value(const Texel& t, const std::vector<Frame>& frames,
                 const std::vector<std::array<double, kSourceBlock>>& x) {
  Vec3 m = t.known;
  for (std::size_t s = 0; s < frames.size(); ++s)
    m += kernel(t, direction_of(frames[s], x[s].data()), x[s][5]).cwiseProduct(Vec3(x[s][2], x[s][3], x[s][4]));
  return m;
}

// Each ball's relative RMS residual, overall and per view, of the known part alone (after =
// false) or with the sources (after = true), into `residuals` (one entry per ball, made on the
// first call).
void record_ball_residuals(const TrustedTexels& all, const std::vector<Frame>& frames,
                           const std::vector<std::array<double, kSourceBlock>>& params, bool after,
                           std::vector<BallResidual>& residuals) {
  const std::size_t balls = all.ball_names.size();
  std::vector<double> num(balls, 0), den(balls, 0);
  std::vector<std::map<int, std::pair<double, double>>> per_view(balls);
  std::vector<long> count(balls, 0);
  for (const Texel& t : all.texels) {
    const Vec3 m = after ? model_value(t, frames, params) : t.known;
    const double w = t.sqrt_w * t.sqrt_w, e = (t.obs - m).squaredNorm(), o = t.obs.squaredNorm();
    num[std::size_t(t.ball)] += w * e, den[std::size_t(t.ball)] += w * o, count[std::size_t(t.ball)] += t.count;
    auto& pv = per_view[std::size_t(t.ball)][t.view];
    pv.first += w * e, pv.second += w * o;
  }
  for (std::size_t b = 0; b < balls; ++b) {
    if (residuals.size() <= b) {
      BallResidual br;
      br.ball = all.ball_names[b];
      br.kind = all.ball_kinds[b];
      br.texels = count[b];
      for (const auto& [v, nd] : per_view[b]) br.views.push_back(all.view_names[std::size_t(v)]);
      residuals.push_back(br);
    }
    BallResidual& br = residuals[b];
    const double rel = den[b] > 0 ? std::sqrt(num[b] / den[b]) : 0;
    (after ? br.after : br.before) = rel;
    auto& list = after ? br.view_after : br.view_before;
    list.clear();
    for (const auto& [v, nd] : per_view[b]) list.push_back(nd.second > 0 ? std::sqrt(nd.first / nd.second) : 0);
  }
}

// Leave-one-view-out solves from the full solution x, one per view (the known part without that
// view's chrome map too, when `known_without` has it: the grey balls' texels re-predicted from it;
// the glossy balls keep the full probe's bake). A fold moves the solution little: a few iterations.
std::vector<std::vector<std::array<double, kSourceBlock>>> jackknife_folds(
    const TrustedTexels& all, const std::vector<Frame>& frames, const std::vector<std::array<double, kSourceBlock>>& x,
    double delta, bool fit_radius, const SourceRecoveryOptions& options,
    const std::map<std::string, EnvMap>& known_without) {
  const std::vector<Texel>& texels = all.texels;
  // The folds are independent problems: solved in parallel, each into its own slot.
  std::vector<std::vector<std::array<double, kSourceBlock>>> folds(all.view_names.size());
  parallel_for_rows(int(all.view_names.size()), [&](int v) {
    std::vector<char> use(texels.size());
    for (std::size_t i = 0; i < texels.size(); ++i) use[i] = texels[i].view != v;
    std::vector<Texel> refolded;
    if (const auto it = known_without.find(all.view_names[std::size_t(v)]); it != known_without.end()) {
      const KnownIrradiance fold_irradiance(it->second, options.known_width);
      refolded = texels;
      parallel_for_rows(int(refolded.size()), [&](int i) {
        Texel& t = refolded[std::size_t(i)];
        if (!t.brdf) t.known = t.gain.cwiseProduct(fold_irradiance(t.n));
      });
    }
    folds[std::size_t(v)] =
        refine(refolded.empty() ? texels : refolded, frames, x, delta, options.refine, fit_radius, false, use, 8).x;
  });
  return folds;
}

struct SourceSigmas {
  Vec3 power = Vec3::Zero();
  double direction = 0, radius = 0;
};

// Source s's sigmas: the larger of the fit's covariance (tangent offsets u ~ angles near u = 0)
// and the jackknife's spread, and for its power the model's misfit as a floor: on the texels this
// source lights, the fit's relative RMS residual r (per channel) is an error of the model
// M = K + P G that the sources cannot be known better than; it moves P by r M / G, i.e.
// sigma >= r P / f with f the source's mean share of M there. (The errors the views share, e.g.
// the probe's known part near the source, escape the covariance and the jackknife; this is where
// they show.)
SourceSigmas source_sigmas(int s, const Fit& fit,
                           const std::vector<std::vector<std::array<double, kSourceBlock>>>& folds,
                           const std::vector<Texel>& texels, const std::vector<Frame>& frames,
                           const std::vector<std::array<double, kSourceBlock>>& x, const LightSource& src,
                           const SourceRecoveryOptions& options) {
  SourceSigmas out;
  const Frame& f = frames[std::size_t(s)];
  const auto& xs = x[std::size_t(s)];
  Vec3& sp = out.power;
  double &sd = out.direction, &sr = out.radius;
  if (fit.covariance_ok) {
    const auto& c = fit.covariance[std::size_t(s)];
    for (int k = 0; k < 3; ++k) sp[k] = std::sqrt(std::max(0.0, c(2 + k, 2 + k)));
    const double cu = std::max(0.0, c(0, 0) + c(1, 1)) / std::pow(1 + xs[0] * xs[0] + xs[1] * xs[1], 2);
    sd = std::sqrt(cu);
    sr = std::sqrt(std::max(0.0, c(5, 5)));
  }
  if (!folds.empty()) {
    const double n = double(folds.size());
    Vec3 jp = Vec3::Zero(), mean = Vec3::Zero();
    for (const auto& fo : folds) mean += Vec3(fo[std::size_t(s)][2], fo[std::size_t(s)][3], fo[std::size_t(s)][4]) / n;
    double jd = 0, jr = 0, mean_r = 0;
    for (const auto& fo : folds) mean_r += fo[std::size_t(s)][5] / n;
    for (const auto& fo : folds) {
      const Vec3 p(fo[std::size_t(s)][2], fo[std::size_t(s)][3], fo[std::size_t(s)][4]);
      jp += (p - mean).cwiseAbs2();
      jd += std::pow(angle_between(direction_of(f, fo[std::size_t(s)].data()), src.direction), 2);
      jr += std::pow(fo[std::size_t(s)][5] - mean_r, 2);
    }
    const double k = (n - 1) / n;
    for (int ch = 0; ch < 3; ++ch) sp[ch] = std::max(sp[ch], std::sqrt(k * jp[ch]));
    sd = std::max(sd, std::sqrt(k * jd));
    sr = std::max(sr, std::sqrt(k * jr));
  }
  // The direction is bounded to its clipped region: where the balls barely see the source (its
  // power near 0) the covariance's angle is unbounded, but the region's radius bounds it.
  sd = std::min(sd, f.max_radius);
  Vec3 num = Vec3::Zero(), den = Vec3::Zero(), share = Vec3::Zero();
  double count = 0;
  for (const Texel& t : texels) {
    const Vec3 g = kernel(t, src.direction, xs[5]);
    if (t.brdf || light_kernels::mean_clamped_cosine(t.n.dot(src.direction), 0.0) <= options.min_lit_kernel) continue;
    const Vec3 m = model_value(t, frames, x);
    const double w = t.sqrt_w * t.sqrt_w;
    for (int ch = 0; ch < 3; ++ch) {
      if (!(m[ch] > 0)) continue;
      num[ch] += w * (t.obs[ch] - m[ch]) * (t.obs[ch] - m[ch]);
      den[ch] += w * m[ch] * m[ch];
      share[ch] += w * g[ch] * src.power[ch] / m[ch];
    }
    count += w;
  }
  for (int ch = 0; ch < 3 && count > 0; ++ch)
    if (den[ch] > 0 && share[ch] > 0)
      sp[ch] = std::max(sp[ch], std::sqrt(num[ch] / den[ch]) * src.power[ch] / (share[ch] / count));
  return out;
}

}  // namespace

SourceRecovery recover_sources(const EnvMap& known, const std::vector<ClippedRegion>& regions,
                               const std::vector<GreyBallMaps>& grey, const std::vector<GlossyBallMaps>& glossy,
                               const SourceRecoveryOptions& options,
                               const std::map<std::string, EnvMap>& known_without) {
  SourceRecovery out;
  if (regions.empty()) return out;
  if (known.layout.kind() != LayoutKind::LatLong) throw std::invalid_argument("sources: the probe must be lat-long");

  TrustedTexels all;
  {
    const KnownIrradiance irradiance(known, options.known_width);
    std::unique_ptr<Integrator> fis;
    for (const GreyBallMaps& g : grey)
      if (g.maps) add_ball_texels(all, g.name, *g.maps, g.albedo, nullptr, known, irradiance, fis, options);
    for (const GlossyBallMaps& g : glossy)
      if (g.maps && g.brdf)
        add_ball_texels(all, g.name, *g.maps, Vec3::Ones(), g.brdf, known, irradiance, fis, options);
  }
  const std::vector<Texel>& texels = all.texels;
  out.texels = 0;
  for (const Texel& t : texels) out.texels += t.count;
  out.fitted_texels = long(texels.size());

  const std::vector<int> chosen = constrained_regions(regions, texels, options, out);
  const int S = int(chosen.size());
  // Each source starts at its region's centroid, its radius the option's (at least a quarter of
  // the region's when glossy balls fit it).
  std::vector<Frame> frames;
  std::vector<std::array<double, kSourceBlock>> x;
  for (int ri : chosen) {
    const ClippedRegion& g = regions[std::size_t(ri)];
    Frame f;
    f.d0 = g.direction.normalized();
    f.t1 = f.d0.unitOrthogonal();
    f.t2 = f.d0.cross(f.t1);
    f.max_radius = std::min(g.radius, 0.5 * kPi);
    f.bound = std::tan(std::min(g.radius, 0.45 * kPi));
    frames.push_back(f);
    x.push_back({0, 0, 0, 0, 0, std::min(std::max(options.radius, 1e-4), std::max(f.max_radius, 2e-4))});
    if (!(options.radius > 0)) x.back()[5] = 0;
  }
  const bool fit_radius = options.refine && !glossy.empty() &&
                          std::any_of(texels.begin(), texels.end(), [](const Texel& t) { return t.brdf != nullptr; });
  if (fit_radius)
    for (int s = 0; s < S; ++s)
      x[std::size_t(s)][5] = std::max(x[std::size_t(s)][5], 0.25 * frames[std::size_t(s)].max_radius);

  record_ball_residuals(all, frames, x, false, out.residuals);
  if (S == 0) {
    record_ball_residuals(all, frames, x, true, out.residuals);
    return out;
  }

  // NNLS at the centroids (plain, then robust with the scale of its residuals), then Ceres.
  solve_powers(texels, frames, x, 0, {});
  std::vector<double> r;
  residuals(texels, frames, x, &r);
  out.robust_sigma = mad_sigma(r);
  const double delta = 3 * std::max(out.robust_sigma, 1e-6);
  solve_powers(texels, frames, x, delta, {});
  Fit fit;
  fit.x = x;
  if (options.refine)
    fit = refine(texels, frames, x, delta, true, fit_radius, true, {});
  else
    fit = refine(texels, frames, x, delta, false, false, true, {});
  x = fit.x;

  std::vector<std::vector<std::array<double, kSourceBlock>>> folds;
  if (options.jackknife && all.view_names.size() >= 3)
    folds = jackknife_folds(all, frames, x, delta, fit_radius, options, known_without);
  record_ball_residuals(all, frames, x, true, out.residuals);

  for (int s = 0; s < S; ++s) {
    const ClippedRegion& g = regions[std::size_t(chosen[std::size_t(s)])];
    const Frame& f = frames[std::size_t(s)];
    const auto& xs = x[std::size_t(s)];
    LightSource src;
    src.direction = direction_of(f, xs.data());
    src.radius = std::max(0.0, xs[5]);
    src.radius_fitted = fit_radius;
    src.power = Vec3(xs[2], xs[3], xs[4]);
    src.region = chosen[std::size_t(s)];
    src.region_solid_angle = g.solid_angle;
    src.region_radius = g.radius;
    src.lower_bound = g.lower_bound;
    const SourceSigmas sigmas = source_sigmas(s, fit, folds, texels, frames, x, src, options);
    src.power_sigma = sigmas.power;
    src.direction_sigma = sigmas.direction;
    src.radius_sigma = fit_radius ? sigmas.radius : 0;
    // The views and balls whose trusted texels it lights.
    std::map<int, long> lit_views;
    std::vector<char> lit_balls(all.ball_names.size(), 0);
    for (const Texel& t : texels)
      if (light_kernels::mean_clamped_cosine(t.n.dot(src.direction), 0.0) > options.min_lit_kernel)
        lit_views[t.view] += t.count, lit_balls[std::size_t(t.ball)] = 1;
    for (const auto& [v, count] : lit_views)
      if (count >= 10) src.views.push_back(all.view_names[std::size_t(v)]);
    for (std::size_t b = 0; b < all.ball_names.size(); ++b)
      if (lit_balls[b]) src.balls.push_back(all.ball_names[b]);
    const bool finite = src.direction.allFinite() && src.power.allFinite() && src.power_sigma.allFinite() &&
                        std::isfinite(src.direction_sigma) && std::isfinite(src.radius) &&
                        std::isfinite(src.radius_sigma);
    if (!finite) {
      out.unrecovered.push_back(src.region);
      out.notes.push_back(describe(g) +
                          ": not recovered: the solve did not give finite values; the probe keeps its lower bound");
      continue;
    }
    out.sources.push_back(src);
  }
  return out;
}

}  // namespace rsibr
